// SPDX-License-Identifier: MIT
#include "rheofeed/motion_law.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace rheofeed {
namespace {

// Below this length (of a unit direction's projection) a belt's direction is taken as normal
// to the contact plane: the contact is on an end face, which does not move along the surface.
constexpr double kBeltEdgeCosine = 1e-6;

[[noreturn]] void refuse(const std::string& where, const std::string& what, double value,
                         const std::string& why) {
  std::ostringstream out;
  out << where << ": " << what << " = " << value << " " << why;
  throw std::invalid_argument(out.str());
}

void requireFinite(const std::string& where, const std::string& what, double value) {
  if (!std::isfinite(value)) refuse(where, what, value, "is not finite");
}

void requireFinite(const std::string& where, const std::string& what, const Vec3& v) {
  requireFinite(where, what + ".x", v.x);
  requireFinite(where, what + ".y", v.y);
  requireFinite(where, what + ".z", v.z);
}

// Names the first non-finite vector of `t` with its value ("twist.linear = (inf, 0, 0)"), or
// returns empty.
std::string firstNonFinite(const Twist& t) {
  const std::pair<const char*, const Vec3*> parts[] = {
      {"twist.linear", &t.linear}, {"twist.angular", &t.angular}, {"twist.origin", &t.origin}};
  for (const auto& [name, v] : parts) {
    if (isFinite(*v)) continue;
    std::ostringstream out;
    out << name << " = (" << v->x << ", " << v->y << ", " << v->z << ")";
    return out.str();
  }
  return {};
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// TimeProfile

TimeProfile TimeProfile::constant(double scale) {
  TimeProfile p;
  p.a_ = scale;
  return p;
}

TimeProfile TimeProfile::ramp(double t_start, double t_end, double from, double to) {
  TimeProfile p;
  p.kind_ = Kind::Ramp;
  p.a_ = t_start;
  p.b_ = t_end;
  p.c_ = from;
  p.d_ = to;
  return p;
}

TimeProfile TimeProfile::onOff(double t_on, double t_off) {
  TimeProfile p;
  p.kind_ = Kind::OnOff;
  p.a_ = t_on;
  p.b_ = t_off;
  return p;
}

TimeProfile TimeProfile::function(std::function<double(double)> scale) {
  TimeProfile p;
  p.kind_ = Kind::Function;
  p.function_ = std::move(scale);
  return p;
}

double TimeProfile::operator()(double t) const {
  switch (kind_) {
    case Kind::Constant:
      return a_;
    case Kind::Ramp:
      if (t <= a_) return c_;
      if (t >= b_) return d_;
      return c_ + (d_ - c_) * (t - a_) / (b_ - a_);
    case Kind::OnOff:
      return (t >= a_ && t < b_) ? 1.0 : 0.0;
    case Kind::Function:
      return function_(t);
  }
  return 0.0;
}

void TimeProfile::validate(const std::string& where) const {
  switch (kind_) {
    case Kind::Constant:
      requireFinite(where, "profile.scale", a_);
      break;
    case Kind::Ramp:
      requireFinite(where, "profile.ramp.t_start", a_);
      requireFinite(where, "profile.ramp.t_end", b_);
      requireFinite(where, "profile.ramp.from", c_);
      requireFinite(where, "profile.ramp.to", d_);
      if (!(b_ > a_)) refuse(where, "profile.ramp.t_end", b_, "must be greater than t_start");
      break;
    case Kind::OnOff:
      requireFinite(where, "profile.on_off.t_on", a_);
      if (std::isnan(b_)) refuse(where, "profile.on_off.t_off", b_, "is not a number");
      if (!(b_ > a_)) refuse(where, "profile.on_off.t_off", b_, "must be greater than t_on");
      break;
    case Kind::Function:
      if (!function_) throw std::invalid_argument(where + ": profile function is empty");
      break;
  }
}

// ---------------------------------------------------------------------------------------------
// MotionLaw

MotionLaw MotionLaw::twist(const Twist& twist, Frame frame) {
  MotionLaw law;
  law.kind_ = Kind::Twist;
  law.frame_ = frame;
  law.twist_ = twist;
  return law;
}

MotionLaw MotionLaw::translation(const Vec3& velocity, Frame frame) {
  return twist(Twist{velocity, {}, {}}, frame);
}

MotionLaw MotionLaw::rotation(const Vec3& angular_velocity, const Vec3& origin, Frame frame) {
  return twist(Twist{{}, angular_velocity, origin}, frame);
}

MotionLaw MotionLaw::belt(const Vec3& direction, double speed, Frame frame) {
  MotionLaw law;
  law.kind_ = Kind::Belt;
  law.frame_ = frame;
  // Normalise without squaring the raw components, which under- or overflows for lengths
  // beyond about 1e+-154. A non-finite or zero direction is kept as given for validate().
  law.twist_.linear = direction;
  const double scale =
      std::fmax(std::fabs(direction.x), std::fmax(std::fabs(direction.y), std::fabs(direction.z)));
  if (isFinite(direction) && scale > 0.0) {
    const Vec3 d{direction.x / scale, direction.y / scale, direction.z / scale};
    law.twist_.linear = (1.0 / norm(d)) * d;
  }
  law.belt_speed_ = speed;
  return law;
}

MotionLaw MotionLaw::field(SurfaceField field, bool time_varying) {
  MotionLaw law;
  law.kind_ = Kind::Field;
  law.field_ = std::move(field);
  law.field_time_varying_ = time_varying;
  return law;
}

MotionLaw MotionLaw::twistFunction(std::function<Twist(double)> twist_of_time, Frame frame) {
  MotionLaw law;
  law.kind_ = Kind::TwistFunction;
  law.frame_ = frame;
  law.twist_function_ = std::move(twist_of_time);
  return law;
}

MotionLaw MotionLaw::withProfile(TimeProfile profile) const {
  MotionLaw law = *this;
  law.profile_ = std::move(profile);
  return law;
}

bool MotionLaw::isTimeVarying() const {
  return !profile_.isConstant() || kind_ == Kind::TwistFunction ||
         (kind_ == Kind::Field && field_time_varying_);
}

void MotionLaw::validate(const std::string& where) const {
  switch (kind_) {
    case Kind::Twist:
      requireFinite(where, "twist.linear", twist_.linear);
      requireFinite(where, "twist.angular", twist_.angular);
      requireFinite(where, "twist.origin", twist_.origin);
      break;
    case Kind::Belt:
      requireFinite(where, "belt.direction", twist_.linear);
      if (isZero(twist_.linear)) {
        throw std::invalid_argument(where + ": belt.direction = (0, 0, 0) has no direction");
      }
      requireFinite(where, "belt.speed", belt_speed_);
      break;
    case Kind::Field:
      if (!field_) throw std::invalid_argument(where + ": field function is empty");
      break;
    case Kind::TwistFunction:
      if (!twist_function_) throw std::invalid_argument(where + ": twist function is empty");
      break;
  }
  profile_.validate(where);
}

StepLaw MotionLaw::evaluate(double t, const Pose* body_pose, double step) const {
  (void)step;  // TODO(issue 7): secant surface velocity of rotating twists
  StepLaw s;
  s.time_ = t;
  s.scale_ = profile_(t);
  if (!std::isfinite(s.scale_)) {
    s.finite_ = false;
    s.problem_ = "profile(" + std::to_string(t) + ") = " + std::to_string(s.scale_);
    return s;
  }
  if (kind_ == Kind::Field) {
    s.eval_ = s.scale_ == 0.0 ? StepLaw::Eval::Zero : StepLaw::Eval::Field;
    s.field_ = &field_;
    s.time_varying_field_ = field_time_varying_;
    return s;
  }

  Twist tw = kind_ == Kind::TwistFunction ? twist_function_(t) : twist_;
  if (kind_ == Kind::TwistFunction) {
    const std::string bad = firstNonFinite(tw);
    if (!bad.empty()) {
      s.finite_ = false;
      s.problem_ = "twist function at t = " + std::to_string(t) + " returned a non-finite " + bad;
      return s;
    }
  }
  const bool body = frame_ == Frame::Body && body_pose != nullptr;
  if (kind_ == Kind::Belt) {
    const double speed = s.scale_ * belt_speed_;
    s.eval_ = speed == 0.0 ? StepLaw::Eval::Zero : StepLaw::Eval::Belt;
    s.v_ = body ? body_pose->rotate(tw.linear) : tw.linear;
    s.w_.x = speed;
    return s;
  }
  const Vec3 v = s.scale_ * tw.linear;
  const Vec3 w = s.scale_ * tw.angular;
  s.v_ = body ? body_pose->rotate(v) : v;
  s.w_ = body ? body_pose->rotate(w) : w;
  s.o_ = body ? body_pose->transform(tw.origin) : tw.origin;
  if (isZero(w)) {
    s.eval_ = isZero(v) ? StepLaw::Eval::Zero : StepLaw::Eval::Translation;
  } else {
    s.eval_ = StepLaw::Eval::Twist;
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// StepLaw

Vec3 StepLaw::tangentialVelocity(const Vec3& p, const Vec3& n) const {
  switch (eval_) {
    case Eval::Zero:
      return {};
    case Eval::Translation:
      return tangentialPart(v_, n);
    case Eval::Twist:
      return tangentialPart(v_ + cross(w_, p - o_), n);
    case Eval::Belt: {
      const Vec3 along = tangentialPart(v_, n);
      const double length = norm(along);
      if (length < kBeltEdgeCosine) return {};
      return (w_.x / length) * along;
    }
    case Eval::Field: {
      const Vec3 c = (*field_)(p, n, time_);
      if (!isFinite(c)) return c;  // as the field gave it, so a report can name the value
      return scale_ * tangentialPart(c, n);
    }
  }
  return {};
}

bool StepLaw::sameMotionAs(const StepLaw& other) const {
  if (eval_ != other.eval_) return false;
  switch (eval_) {
    case Eval::Zero:
      return true;
    case Eval::Field:
      return field_ == other.field_ && scale_ == other.scale_ && !time_varying_field_;
    default:
      return v_ == other.v_ && w_ == other.w_ && o_ == other.o_;
  }
}

}  // namespace rheofeed
