// SPDX-License-Identifier: MIT
#include "rheofeed/motion_law.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "current_exception.hpp"

namespace rheofeed {
namespace {

// Below this length (of a unit direction's projection) a belt's direction is taken as normal
// to the contact plane: the contact is on an end face, which does not move along the surface.
constexpr double kBeltEdgeCosine = 1e-6;

// Below this turn per step (rad) the secant's coefficients sin(theta)/theta and
// (1 - cos(theta))/theta^2 are taken from their Taylor series (then exact to double rounding,
// and free of 0/0 when |w| h underflows).
constexpr double kSeriesAngle = 1e-4;

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

// Refuses |v| beyond `limit` (v finite; hypot does not overflow on the way).
void requireNormWithin(const std::string& where, const std::string& what, const Vec3& v,
                       double limit, const char* unit) {
  const double length = std::hypot(v.x, v.y, v.z);
  if (length <= limit) return;
  std::ostringstream out;
  out << where << ": |" << what << "| = " << length << " " << unit
      << " is beyond the limit: must be in [0, " << limit << "] " << unit;
  throw std::invalid_argument(out.str());
}

void requireComponentsWithin(const std::string& where, const std::string& what, const Vec3& v,
                             double limit, const char* unit) {
  const std::pair<const char*, double> parts[] = {{".x", v.x}, {".y", v.y}, {".z", v.z}};
  for (const auto& [axis, value] : parts) {
    if (std::fabs(value) <= limit) continue;
    std::ostringstream out;
    out << where << ": " << what << axis << " = " << value << " " << unit
        << " is beyond the limit: must be in [" << -limit << ", " << limit << "] " << unit;
    throw std::invalid_argument(out.str());
  }
}

// The first value of a frozen twist beyond the limits (v, w world; o the origin), or empty.
std::string firstBeyondLimits(const Vec3& v, const Vec3& w, const Vec3& o) {
  std::ostringstream out;
  const double speed = std::hypot(v.x, v.y, v.z), spin = std::hypot(w.x, w.y, w.z);
  if (!(speed <= kMaxSurfaceSpeed)) {
    out << "|twist.linear| = " << speed << " m/s is beyond the limit [0, " << kMaxSurfaceSpeed
        << "] m/s";
  } else if (!(spin <= kMaxAngularSpeed)) {
    out << "|twist.angular| = " << spin << " rad/s is beyond the limit [0, " << kMaxAngularSpeed
        << "] rad/s";
  } else if (!(std::fmax(std::fabs(o.x), std::fmax(std::fabs(o.y), std::fabs(o.z))) <=
               kMaxOriginCoordinate)) {
    out << "twist.origin = (" << o.x << ", " << o.y << ", " << o.z
        << ") m is beyond the limit: coordinates in [" << -kMaxOriginCoordinate << ", "
        << kMaxOriginCoordinate << "] m";
  }
  return out.str();
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

TimeProfile TimeProfile::product(TimeProfile a, TimeProfile b) {
  if (a.kind_ == Kind::Constant && b.kind_ == Kind::Constant) return constant(a.a_ * b.a_);
  if (a.kind_ == Kind::Constant && a.a_ == 1.0) return b;
  if (b.kind_ == Kind::Constant && b.a_ == 1.0) return a;
  // One flat list of factors (no nesting however many profiles are multiplied in), the
  // constants folded into one.
  TimeProfile p;
  p.kind_ = Kind::Product;
  double scale = 1.0;
  for (TimeProfile* f : {&a, &b}) {
    if (f->kind_ == Kind::Product) {
      for (TimeProfile& g : f->factors_) {
        if (g.kind_ == Kind::Constant) {
          scale *= g.a_;
        } else {
          p.factors_.push_back(std::move(g));
        }
      }
    } else if (f->kind_ == Kind::Constant) {
      scale *= f->a_;
    } else {
      p.factors_.push_back(std::move(*f));
    }
  }
  if (scale != 1.0) p.factors_.push_back(constant(scale));
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
    case Kind::Product: {
      double s = 1.0;
      for (const TimeProfile& f : factors_) s *= f(t);
      return s;
    }
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
    case Kind::Product:
      for (const TimeProfile& f : factors_) f.validate(where);
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

MotionLaw MotionLaw::localVibration(const LocalVibration& vibration,
                                    const PointMassSettings& settings) {
  return localVibration(vibration, std::make_shared<LocalDriftTable>(settings));
}

MotionLaw MotionLaw::localVibration(const LocalVibration& vibration,
                                    std::shared_ptr<LocalDriftTable> table) {
  if (!table) throw std::invalid_argument("MotionLaw::localVibration: the drift table is null");
  MotionLaw law;
  law.kind_ = Kind::LocalVibration;
  law.local_ = std::make_shared<const LocalVibration>(vibration);
  law.table_ = std::move(table);
  return law;
}

LocalDriftStats MotionLaw::localStats() const {
  return table_ ? table_->stats() : LocalDriftStats{};
}

MotionLaw MotionLaw::withProfile(TimeProfile profile) const {
  MotionLaw law = *this;
  law.profile_ = TimeProfile::product(profile_, std::move(profile));
  return law;
}

bool MotionLaw::isTimeVarying() const {
  return !profile_.isConstant() || kind_ == Kind::TwistFunction ||
         (kind_ == Kind::Field && field_time_varying_);
}

double TimeProfile::largestConstantValue() const {
  switch (kind_) {
    case Kind::Constant:
      return std::fabs(a_);
    case Kind::Ramp:
      return std::fmax(std::fabs(c_), std::fabs(d_));
    case Kind::OnOff:
      return 1.0;
    case Kind::Function:
      return 1.0;  // unknown here: checked each step
    case Kind::Product: {
      double s = 1.0;
      for (const TimeProfile& f : factors_) s *= f.largestConstantValue();
      return s;
    }
  }
  return 1.0;
}

void MotionLaw::validate(const std::string& where) const {
  switch (kind_) {
    case Kind::Twist:
      requireFinite(where, "twist.linear", twist_.linear);
      requireFinite(where, "twist.angular", twist_.angular);
      requireFinite(where, "twist.origin", twist_.origin);
      requireNormWithin(where, "twist.linear", twist_.linear, kMaxSurfaceSpeed, "m/s");
      requireNormWithin(where, "twist.angular", twist_.angular, kMaxAngularSpeed, "rad/s");
      requireComponentsWithin(where, "twist.origin", twist_.origin, kMaxOriginCoordinate, "m");
      break;
    case Kind::Belt:
      requireFinite(where, "belt.direction", twist_.linear);
      if (isZero(twist_.linear)) {
        throw std::invalid_argument(where + ": belt.direction = (0, 0, 0) has no direction");
      }
      requireFinite(where, "belt.speed", belt_speed_);
      if (!(std::fabs(belt_speed_) <= kMaxSurfaceSpeed)) {
        std::ostringstream out;
        out << "m/s is beyond the limit: must be in [" << -kMaxSurfaceSpeed << ", "
            << kMaxSurfaceSpeed << "] m/s";
        refuse(where, "belt.speed", belt_speed_, out.str());
      }
      break;
    case Kind::Field:
      if (!field_) throw std::invalid_argument(where + ": field function is empty");
      break;
    case Kind::TwistFunction:
      if (!twist_function_) throw std::invalid_argument(where + ": twist function is empty");
      break;
    case Kind::LocalVibration:
      if (frame_ != Frame::World) {
        throw std::invalid_argument(where + ": a local vibration law is in the world frame");
      }
      local_->validate(where);
      break;
  }
  profile_.validate(where);
  // The profile scales every speed: the scaled constant law must stay within the limits too.
  const double scale = profile_.largestConstantValue();
  if (scale > 1.0 && (kind_ == Kind::Twist || kind_ == Kind::Belt)) {
    const double speed = kind_ == Kind::Belt
                             ? std::fabs(belt_speed_)
                             : std::hypot(twist_.linear.x, twist_.linear.y, twist_.linear.z);
    const double spin = kind_ == Kind::Belt
                            ? 0.0
                            : std::hypot(twist_.angular.x, twist_.angular.y, twist_.angular.z);
    if (!(scale * speed <= kMaxSurfaceSpeed) || !(scale * spin <= kMaxAngularSpeed)) {
      const bool linear = !(scale * speed <= kMaxSurfaceSpeed);
      std::ostringstream out;
      out << where << ": profile value " << scale << " times "
          << (linear ? (kind_ == Kind::Belt ? "|belt.speed| = " : "|twist.linear| = ")
                     : "|twist.angular| = ")
          << (linear ? speed : spin) << (linear ? " m/s" : " rad/s") << " gives "
          << scale * (linear ? speed : spin) << (linear ? " m/s" : " rad/s")
          << ", beyond the limit: must be in [0, " << (linear ? kMaxSurfaceSpeed : kMaxAngularSpeed)
          << (linear ? "] m/s" : "] rad/s");
      throw std::invalid_argument(out.str());
    }
  }
}

StepLaw MotionLaw::evaluate(double t, const Pose* body_pose, double step) const {
  StepLaw s;
  s.time_ = t;
  if (!(step >= 0.0) || !std::isfinite(step)) {
    s.finite_ = false;
    std::ostringstream out;
    out << "step = " << step << " s is not finite and >= 0";
    s.problem_ = out.str();
    return s;
  }
  // A user function that throws gives a law that is not finite: evaluate runs inside ODE's
  // near callback (through FeederSet::driveContacts), where no exception may pass.
  try {
    s.scale_ = profile_(t);
  } catch (...) {
    s.finite_ = false;
    s.threw_ = true;
    s.problem_ = "profile function threw at t = " + std::to_string(t) + ": " +
                 detail::currentExceptionMessage();
    return s;
  }
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

  if (kind_ == Kind::LocalVibration) {
    s.eval_ = s.scale_ == 0.0 ? StepLaw::Eval::Zero : StepLaw::Eval::Local;
    s.local_ = local_.get();
    s.table_ = table_.get();
    return s;
  }

  Twist tw = twist_;
  if (kind_ == Kind::TwistFunction) {
    try {
      tw = twist_function_(t);
    } catch (...) {
      s.finite_ = false;
      s.threw_ = true;
      s.problem_ = "twist function threw at t = " + std::to_string(t) + ": " +
                   detail::currentExceptionMessage();
      return s;
    }
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
    if (!(std::fabs(speed) <= kMaxSurfaceSpeed)) {
      std::ostringstream out;
      out << "profile(" << t << ") = " << s.scale_ << " times belt.speed = " << belt_speed_
          << " m/s gives " << speed << " m/s, beyond the limit [" << -kMaxSurfaceSpeed << ", "
          << kMaxSurfaceSpeed << "] m/s";
      s.finite_ = false;
      s.problem_ = out.str();
      return s;
    }
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
  const std::string beyond = firstBeyondLimits(s.v_, s.w_, s.o_);
  if (!beyond.empty()) {
    std::ostringstream out;
    out << (kind_ == Kind::TwistFunction ? "twist function" : "twist") << " at t = " << t;
    if (s.scale_ != 1.0) out << " times profile " << s.scale_;
    out << ": " << beyond;
    s.finite_ = false;
    s.problem_ = out.str();
    s.eval_ = StepLaw::Eval::Zero;
    return s;
  }
  if (isZero(w)) {
    s.eval_ = isZero(v) ? StepLaw::Eval::Zero : StepLaw::Eval::Translation;
  } else if (step > 0.0) {
    s.freezeSecant(step);
  } else {
    s.eval_ = StepLaw::Eval::Twist;
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// StepLaw

// The secant of a twist over a step (see the derivation in motion_law.hpp). With w = |w| u,
// theta = |w| h and K = [w]x (K p = w x p), Rodrigues gives
//   R(w h) - I = sin(theta) [u]x + (1 - cos(theta)) [u]x^2
//   M = (R - I) / h = a K + b h K^2,  a = sin(theta) / theta,  b = (1 - cos(theta)) / theta^2,
// with K^2 = w w^T - |w|^2 I. The flow of v_par + w x (p - O') with O' = O + (w x v) / |w|^2
// moves p by h c(p), c(p) = v_par + M (p - O'). Since M (w x v) / |w|^2 = -a v_perp - b h (w x v)
// (from K (w x v) = -|w|^2 v_perp and K^2 (w x v) = -|w|^2 (w x v)), the same c is
//   c(p) = M (p - O) + d,   d = v_par + a v_perp + b h (w x v),
// which needs no division by |w|^2 (O' runs off to infinity as w -> 0) and keeps p - O small.
// As h -> 0, a -> 1 and b h -> 0: M -> K and d -> v, the instantaneous field v + w x (p - O).
void StepLaw::freezeSecant(double h) {
  const double speed = norm(w_);
  const double theta = speed * h;
  double a, b;
  if (theta < kSeriesAngle) {
    // Taylor series; the first omitted terms, theta^4 / 120 and theta^4 / 720, are below
    // double rounding for theta < kSeriesAngle.
    a = 1.0 - theta * theta / 6.0;
    b = 0.5 - theta * theta / 24.0;
  } else {
    a = std::sin(theta) / theta;
    const double half = std::sin(0.5 * theta) / (0.5 * theta);
    b = 0.5 * half * half;  // (1 - cos(theta)) / theta^2 without cancellation
  }
  const double ww[3] = {w_.x, w_.y, w_.z};
  const double w2 = dot(w_, w_);
  const double bh = b * h;
  // M = a K + b h (w w^T - |w|^2 I), row-major.
  const double k[9] = {0, -w_.z, w_.y, w_.z, 0, -w_.x, -w_.y, w_.x, 0};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      m_[3 * i + j] = a * k[3 * i + j] + bh * (ww[i] * ww[j] - (i == j ? w2 : 0.0));
    }
  }
  const Vec3 u = (1.0 / speed) * w_;
  const Vec3 v_par = dot(v_, u) * u;
  d_ = v_par + a * (v_ - v_par) + bh * cross(w_, v_);
  step_ = h;
  eval_ = Eval::Secant;
}

Vec3 StepLaw::tangentialVelocity(const Vec3& p, const Vec3& n) const {
  switch (eval_) {
    case Eval::Zero:
      return {};
    case Eval::Translation:
      return tangentialPart(v_, n);
    case Eval::Twist:
      return tangentialPart(v_ + cross(w_, p - o_), n);
    case Eval::Secant:
      return tangentialPart(secant(p), n);
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
    case Eval::Local:
      return contactVelocity(p, n, local_->mu);
  }
  return {};
}

Vec3 StepLaw::contactVelocity(const Vec3& p_contact, const Vec3& n_out, double mu,
                              double efficiency, const Vec3* carried) const {
  if (eval_ != Eval::Local) return tangentialVelocity(p_contact, n_out);
  if (local_->isTranslation()) {  // the drift does not depend on the point
    if (!(memo_valid_ && n_out == memo_n_ && mu == memo_mu_)) {
      memo_value_ = localDrift(*local_, p_contact, n_out, mu, table_, &memo_wall_);
      memo_n_ = n_out;
      memo_mu_ = mu;
      memo_valid_ = true;
    } else {
      table_->countContacts(1, memo_wall_ ? 1 : 0);
    }
    return (scale_ * efficiency) * memo_value_;
  }
  const Vec3 p = carried ? *carried - dot(*carried - p_contact, n_out) * n_out : p_contact;
  return (scale_ * efficiency) * localDrift(*local_, p, n_out, mu, table_);
}

Vec3 StepLaw::tangentialVelocity(const Vec3& p, const Vec3& n, const Vec3& carried) const {
  if (eval_ != Eval::Secant) return tangentialVelocity(p, n);
  // The rigid motion that takes the carried point along its secant and turns at w.
  return tangentialPart(secant(carried) + cross(w_, p - carried), n);
}

Vec3 StepLaw::secant(const Vec3& p) const {
  const Vec3 r = p - o_;
  const double* m = m_;
  return {m[0] * r.x + m[1] * r.y + m[2] * r.z + d_.x, m[3] * r.x + m[4] * r.y + m[5] * r.z + d_.y,
          m[6] * r.x + m[7] * r.y + m[8] * r.z + d_.z};
}

bool StepLaw::sameMotionAs(const StepLaw& other) const {
  if (eval_ != other.eval_) return false;
  switch (eval_) {
    case Eval::Zero:
      return true;
    case Eval::Field:
      return field_ == other.field_ && scale_ == other.scale_ && !time_varying_field_;
    case Eval::Local:
      return local_ == other.local_ && scale_ == other.scale_;
    default:  // a secant also depends on the step length
      return v_ == other.v_ && w_ == other.w_ && o_ == other.o_ && step_ == other.step_;
  }
}

namespace {

// Norm of the vector part of a quaternion when it is below the machine epsilon: the largest
// component times the norm of the vector divided by it (no underflow of the squares).
double smallVectorNorm(double x, double y, double z) {
  const double largest = std::max(std::abs(x), std::max(std::abs(y), std::abs(z)));
  if (!(largest > 0.0)) return largest == 0.0 ? 0.0 : largest;  // 0, or NaN kept
  double inverse = 1.0 / largest, scale = largest;
  if (inverse > std::numeric_limits<double>::max()) {
    inverse = std::numeric_limits<double>::max();
    scale = 1.0 / inverse;
  }
  const double a = x * inverse, b = y * inverse, c = z * inverse;
  return scale * std::sqrt(a * a + b * b + c * c);
}

}  // namespace

// The rotation R = R1 R0^T as a unit quaternion (Shoemake's method: from the trace when it is
// positive, else from the largest diagonal entry), then as an axis and the angle
// 2 atan2(|q_vec|, |q_w|) in [0, pi] with the axis's sign following q_w.
Vec3 secantAngularVelocity(const Pose& p0, const Pose& p1, double h) {
  const double* a = p1.rotation;
  const double* b = p0.rotation;
  // The sums are grouped as the reference world's earlier Eigen form grouped them (rows 0 and 1
  // left to right, row 2 and the trace from the right), so that kinematic bodies keep their
  // trajectories to the bit.
  double m[3][3];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double t0 = a[3 * i] * b[3 * j], t1 = a[3 * i + 1] * b[3 * j + 1],
                   t2 = a[3 * i + 2] * b[3 * j + 2];
      m[i][j] = i < 2 ? (t0 + t1) + t2 : t0 + (t1 + t2);
    }
  }
  double q[3];  // vector part (x, y, z)
  double w;
  double t = m[0][0] + (m[1][1] + m[2][2]);
  if (t > 0.0) {
    t = std::sqrt(t + 1.0);
    w = 0.5 * t;
    t = 0.5 / t;
    q[0] = (m[2][1] - m[1][2]) * t;
    q[1] = (m[0][2] - m[2][0]) * t;
    q[2] = (m[1][0] - m[0][1]) * t;
  } else {
    int i = 0;
    if (m[1][1] > m[0][0]) i = 1;
    if (m[2][2] > m[i][i]) i = 2;
    const int j = (i + 1) % 3, k = (j + 1) % 3;
    t = std::sqrt(m[i][i] - m[j][j] - m[k][k] + 1.0);
    q[i] = 0.5 * t;
    t = 0.5 / t;
    w = (m[k][j] - m[j][k]) * t;
    q[j] = (m[j][i] + m[i][j]) * t;
    q[k] = (m[k][i] + m[i][k]) * t;
  }
  double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
  if (n < std::numeric_limits<double>::epsilon()) n = smallVectorNorm(q[0], q[1], q[2]);
  double angle = 0.0;
  Vec3 axis{1.0, 0.0, 0.0};
  if (n != 0.0) {
    angle = 2.0 * std::atan2(n, std::abs(w));
    if (w < 0.0) n = -n;
    axis = {q[0] / n, q[1] / n, q[2] / n};
  }
  const double rate = angle / h;
  return {axis.x * rate, axis.y * rate, axis.z * rate};
}

Vec3 contactSurfaceVelocity(const StepLaw& law, const Vec3& p, const Vec3& n, const Vec3& n_out,
                            double mu, double efficiency, const Vec3* carried) {
  if (law.needsContactSide()) return law.contactVelocity(p, n_out, mu, efficiency, carried);
  if (carried && law.usesCarriedPoint()) return law.tangentialVelocity(p, n, *carried);
  return law.tangentialVelocity(p, n);
}

}  // namespace rheofeed
