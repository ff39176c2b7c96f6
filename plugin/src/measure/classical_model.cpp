// SPDX-License-Identifier: MIT
// The classical single-part feeder model (Redford & Boothroyd), integrated in closed form
// between events. See classical_model.hpp for the equations.
//
// Dimensionless form. With the phase phi = w t, velocities in units of g / w and lengths in
// units of g / w^2, every acceleration (in units of g) has the form p + q sin(phi):
//   free tangential (no friction):  a(phi) = -sin(alpha) + G_t sin(phi),  G_t = A w^2 cos(beta)/g
//   normal force per mass:          N(phi) =  cos(alpha) - G_n sin(phi),  G_n = A w^2 sin(beta)/g
//   sliding with s = sign(u):       a(phi) - s mu N(phi)
//   flight, normal relative motion: y'' = -N(phi)
// and over a phase that starts at phi0 with velocity v0 and position x0 (tau = phi - phi0):
//   v(phi) = v0 + p tau - q (cos(phi) - cos(phi0))
//   x(phi) = x0 + v0 tau + p tau^2 / 2 - q (sin(phi) - sin(phi0) - tau cos(phi0)).
// Events:
//   stick -> slide up-track    g+(phi) = a - mu N   crosses 0     (roots of p + q sin: analytic)
//   stick -> slide down-track  g-(phi) = a + mu N   crosses 0     (analytic)
//   contact -> flight          N(phi) crosses 0                   (analytic)
//   slide -> stick / reversal  u(phi) = 0: u is monotone between the analytic roots of u', so
//                              each such interval holds at most one root, bracketed exactly
//   flight -> landing          y(phi) = 0: y'' has analytic roots; between them y' is monotone
//                              (its root, if any, is bracketed); between all of these y is
//                              monotone and its first root is bracketed.
// After every event the new phase is decided from the state a little after the event
// (kLookAhead), which also settles grazing cases (a root where the function only touches 0).
#include "rheofeed/measure/classical_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace rheofeed::scene {
namespace {

constexpr double kTwoPi = 2 * kPi;
// Roots of an event function closer than this (rad of phase) to the start of a search are the
// event just handled, not a new one.
constexpr double kRootGuard = 1e-11;
// After an event the new phase is decided from the functions this far ahead (rad of phase):
// beyond kRootGuard, far below any physical time scale of a cycle.
constexpr double kLookAhead = 1e-9;
// Cap on events within one cycle; a correct run has a handful. Reaching it means a Zeno-like
// chatter that the model cannot resolve (reported as an exception, never seen in practice).
constexpr int kMaxEventsPerCycle = 10000;
// Two unit vectors are orthogonal when their dot product is below this.
constexpr double kOrthogonality = 1e-9;

enum class Phase { Stick, SlideUp, SlideDown, Flight };

// p + q sin(phi).
struct SineLaw {
  double p = 0, q = 0;
  double operator()(double phi) const { return p + q * std::sin(phi); }
  // Velocity and position after integrating from phi0 (tau = phi - phi0).
  double velocity(double v0, double phi0, double phi) const {
    return v0 + p * (phi - phi0) - q * (std::cos(phi) - std::cos(phi0));
  }
  double position(double x0, double v0, double phi0, double phi) const {
    const double tau = phi - phi0;
    return x0 + v0 * tau + 0.5 * p * tau * tau -
           q * (std::sin(phi) - std::sin(phi0) - tau * std::cos(phi0));
  }
};

// Event candidates in a search window of at most one cycle: at most nine arise (three sine
// laws with up to three roots each, or the roots of y'' and y'), so 16 is never exceeded.
struct Points {
  std::array<double, 16> at{};
  int n = 0;
  void add(double v) {
    if (n < static_cast<int>(at.size())) at[n++] = v;
  }
  void sort() { std::sort(at.begin(), at.begin() + n); }
};

// Roots of p + q sin(phi) in (a, b] (b - a <= 2 pi), appended unsorted.
void sineRoots(const SineLaw& f, double a, double b, Points& out) {
  if (f.q == 0) return;
  const double s = -f.p / f.q;
  if (!(std::abs(s) <= 1)) return;
  const double r1 = std::asin(s), r2 = kPi - r1;
  for (double r : {r1, r2}) {
    double k = std::ceil((a - r) / kTwoPi);
    for (double phi = r + k * kTwoPi; phi <= b; phi += kTwoPi) {
      if (phi > a) out.add(phi);
    }
  }
}

// The first point of (lo, hi] where f <= 0, given f(lo) > 0 (or lo the start of a phase whose
// function leaves 0 upwards) and f(hi) <= 0 with f monotone on [lo, hi]. Bisection to rounding.
template <class F>
double bisectDown(const F& f, double lo, double hi) {
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (!(mid > lo && mid < hi)) break;
    if (f(mid) > 0) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return hi;
}

// The root of f in [lo, hi] given f(lo) and f(hi) of strictly opposite signs.
template <class F>
double bisectSign(const F& f, double lo, double hi) {
  const bool lo_positive = f(lo) > 0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (!(mid > lo && mid < hi)) break;
    if ((f(mid) > 0) == lo_positive) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

// The first point in (a, b] where f, positive just after a, becomes <= 0, with f monotone
// between consecutive points of `breaks` (sorted, inside (a, b)). False when there is none.
template <class F>
bool firstDownCrossing(const F& f, const Points& breaks, double a, double b, double& root) {
  double left = a;
  for (int i = 0; i <= breaks.n; ++i) {
    const double right = i < breaks.n ? breaks.at[i] : b;
    if (right <= left) continue;
    if (f(right) <= 0) {
      root = bisectDown(f, left, right);
      return true;
    }
    left = right;
  }
  return false;
}

struct CycleStats {
  double displacement = 0;  // dimensionless (g / w^2)
  double time[4] = {};      // rad of phase per Phase
};

struct CycleStart {
  Phase phase;
  double u, y, v;
};

class Model {
 public:
  explicit Model(const ClassicalParams& p) : mu_(p.mu) {
    const double w = kTwoPi * p.frequency;
    const double aw2 = p.amplitude * w * w / p.gravity;
    sin_alpha_ = std::sin(p.track_angle);
    cos_alpha_ = std::cos(p.track_angle);
    g_t_ = aw2 * std::cos(p.vibration_angle);
    g_n_ = aw2 * std::sin(p.vibration_angle);
  }

  // Runs one cycle from phase 0 to 2 pi; returns its statistics.
  CycleStats cycle(int& events) {
    CycleStats stats;
    const double x_start = x_;
    int count = 0;
    while (phi_ < kTwoPi) {
      if (++count > kMaxEventsPerCycle) {
        throw std::runtime_error("classicalDrift: more than " + std::to_string(kMaxEventsPerCycle) +
                                 " events in one cycle (unresolved chatter)");
      }
      double next = kTwoPi;
      const Event e = nextEvent(kTwoPi, next);
      stats.time[static_cast<int>(phase_)] += next - phi_;
      advance(next);
      if (e == Event::None) break;
      ++events;
      handle(e);
    }
    phi_ = 0;  // the dynamics are 2 pi periodic in the phase
    stats.displacement = x_ - x_start;
    return stats;
  }

  // Starts at phase 0 at rest on the track.
  void start() {
    phi_ = 0;
    x_ = u_ = y_ = v_ = 0;
    phase_ = Phase::Stick;
    decideContact();
  }

  CycleStart cycleStart() const { return {phase_, u_, y_, v_}; }

 private:
  enum class Event { None, Reconsider, SlideEnd, Landing };

  SineLaw normal() const { return {cos_alpha_, -g_n_}; }
  SineLaw free() const { return {-sin_alpha_, g_t_}; }
  SineLaw upLimit() const {  // a - mu N: > 0 drives up-track sliding
    return {-sin_alpha_ - mu_ * cos_alpha_, g_t_ + mu_ * g_n_};
  }
  SineLaw downLimit() const {  // a + mu N: < 0 drives down-track sliding
    return {-sin_alpha_ + mu_ * cos_alpha_, g_t_ - mu_ * g_n_};
  }
  SineLaw tangential() const {
    switch (phase_) {
      case Phase::Stick:
        return {0, 0};
      case Phase::SlideUp:
        return upLimit();
      case Phase::SlideDown:
        return downLimit();
      case Phase::Flight:
        return free();
    }
    return {0, 0};
  }
  SineLaw normalAcceleration() const { return {-cos_alpha_, g_n_}; }  // y'' in flight

  void advance(double phi) {
    const SineLaw t = tangential();
    x_ = t.position(x_, u_, phi_, phi);
    u_ = phase_ == Phase::Stick ? 0.0 : t.velocity(u_, phi_, phi);
    if (phase_ == Phase::Flight) {
      const SineLaw n = normalAcceleration();
      y_ = n.position(y_, v_, phi_, phi);
      v_ = n.velocity(v_, phi_, phi);
    }
    phi_ = phi;
  }

  // The first event in (phi_, end]; `at` receives its phase (end when there is none).
  Event nextEvent(double end, double& at) const {
    const double a = phi_, guard = phi_ + kRootGuard;
    at = end;
    Event event = Event::None;
    auto consider = [&](const Points& roots, Event kind) {
      for (int i = 0; i < roots.n; ++i) {
        if (roots.at[i] > guard && roots.at[i] < at) {
          at = roots.at[i];
          event = kind;
        }
      }
    };
    if (phase_ == Phase::Flight) {
      double root;
      if (landing(a, end, root) && root < at) {
        at = root;
        event = Event::Landing;
      }
      return event;
    }
    Points analytic;
    sineRoots(normal(), a, end, analytic);  // lift-off
    if (phase_ == Phase::Stick) {
      sineRoots(upLimit(), a, end, analytic);
      sineRoots(downLimit(), a, end, analytic);
    }
    consider(analytic, Event::Reconsider);
    if (phase_ != Phase::Stick) {
      // u, signed so that it is > 0 while sliding, is monotone between the roots of u'.
      const SineLaw t = tangential();
      const double s = phase_ == Phase::SlideUp ? 1.0 : -1.0;
      Points breaks;
      sineRoots(t, guard, end, breaks);
      breaks.sort();
      const double phi0 = phi_, u0 = u_;
      auto su = [&](double phi) { return s * t.velocity(u0, phi0, phi); };
      double root;
      if (firstDownCrossing(su, breaks, a, end, root) && root < at) {
        at = root;
        event = Event::SlideEnd;
      }
    }
    return event;
  }

  // First landing (y back to 0 from above) in (a, end].
  bool landing(double a, double end, double& root) const {
    const SineLaw n = normalAcceleration();
    const double phi0 = phi_, y0 = y_, v0 = v_;
    auto y = [&](double phi) { return n.position(y0, v0, phi0, phi); };
    auto yd = [&](double phi) { return n.velocity(v0, phi0, phi); };
    Points curvature;  // roots of y''
    sineRoots(n, a + kRootGuard, end, curvature);
    curvature.sort();
    Points breaks = curvature;  // plus roots of y', one at most between roots of y''
    double left = a;
    for (int i = 0; i <= curvature.n; ++i) {
      const double right = i < curvature.n ? curvature.at[i] : end;
      const double fl = yd(left), fr = yd(right);
      if ((fl > 0 && fr < 0) || (fl < 0 && fr > 0)) breaks.add(bisectSign(yd, left, right));
      left = right;
    }
    breaks.sort();
    return firstDownCrossing(y, breaks, a, end, root);
  }

  void handle(Event e) {
    switch (e) {
      case Event::None:
        return;
      case Event::Reconsider:
        decideContact();
        return;
      case Event::SlideEnd:
        u_ = 0;
        decideContact();
        return;
      case Event::Landing: {
        // Plastic impact: normal impulse P = -v (per mass) kills the normal relative velocity;
        // friction impulse at most mu P reduces |u| towards 0.
        const double impulse = std::max(-v_, 0.0);
        const double reduced = std::max(std::abs(u_) - mu_ * impulse, 0.0);
        u_ = std::copysign(reduced, u_);
        y_ = v_ = 0;
        phase_ = Phase::Stick;  // in contact; decided below
        decideContact();
        return;
      }
    }
  }

  // New phase of a part on the track (y = 0) at phi_, from the state just after phi_.
  void decideContact() {
    const double ahead = phi_ + kLookAhead;
    if (normal()(ahead) <= 0) {
      phase_ = Phase::Flight;
      y_ = v_ = 0;
    } else if (u_ > 0) {
      phase_ = Phase::SlideUp;
    } else if (u_ < 0) {
      phase_ = Phase::SlideDown;
    } else if (upLimit()(ahead) > 0) {
      phase_ = Phase::SlideUp;
    } else if (downLimit()(ahead) < 0) {
      phase_ = Phase::SlideDown;
    } else {
      phase_ = Phase::Stick;
    }
  }

  double mu_;
  double sin_alpha_ = 0, cos_alpha_ = 1, g_t_ = 0, g_n_ = 0;
  double phi_ = 0, x_ = 0, u_ = 0, y_ = 0, v_ = 0;
  Phase phase_ = Phase::Stick;
};

[[noreturn]] void bad(const std::string& name, double value, const std::string& why) {
  std::ostringstream out;
  out << name << " = " << value << ": " << why;
  throw std::invalid_argument(out.str());
}

bool sameStart(const CycleStart& a, const CycleStart& b, double tol) {
  return a.phase == b.phase && std::abs(a.u - b.u) <= tol && std::abs(a.y - b.y) <= tol &&
         std::abs(a.v - b.v) <= tol;
}

}  // namespace

void ClassicalParams::validate() const {
  auto finite = [](const char* name, double v) {
    if (!std::isfinite(v)) bad(name, v, "must be finite");
  };
  finite("track_angle", track_angle);
  finite("vibration_angle", vibration_angle);
  if (!(mu > 0) || !std::isfinite(mu)) bad("mu", mu, "must be a finite number > 0");
  if (!(std::abs(track_angle) < 0.5 * kPi))
    bad("track_angle", track_angle, "must be in (-pi/2, pi/2)");
  if (!(std::abs(std::tan(track_angle)) < mu)) {
    bad("track_angle", track_angle,
        "|tan(track_angle)| must be < mu = " + std::to_string(mu) +
            " (the part would slide along the track without vibration: no steady state)");
  }
  if (!(vibration_angle > 0 && vibration_angle < 0.5 * kPi)) {
    bad("vibration_angle", vibration_angle, "must be in (0, pi/2) rad");
  }
  if (!(amplitude > 0) || !std::isfinite(amplitude)) {
    bad("amplitude", amplitude, "must be a finite number > 0 (m)");
  }
  if (!(frequency > 0) || !std::isfinite(frequency)) {
    bad("frequency", frequency, "must be a finite number > 0 (Hz)");
  }
  if (!(gravity > 0) || !std::isfinite(gravity)) {
    bad("gravity", gravity, "must be a finite number > 0 (m/s^2)");
  }
  if (max_cycles < 2) bad("max_cycles", max_cycles, "must be >= 2");
  if (average_cycles < 1 || average_cycles > max_cycles) {
    bad("average_cycles", average_cycles, "must be in [1, max_cycles]");
  }
  if (max_period < 1) bad("max_period", max_period, "must be >= 1");
  if (!(periodic_tolerance > 0) || !std::isfinite(periodic_tolerance)) {
    bad("periodic_tolerance", periodic_tolerance, "must be a finite number > 0");
  }
}

const char* toString(ClassicalRegime regime) {
  switch (regime) {
    case ClassicalRegime::NoMotion:
      return "no_motion";
    case ClassicalRegime::ForwardSliding:
      return "forward_sliding";
    case ClassicalRegime::BackwardSliding:
      return "backward_sliding";
    case ClassicalRegime::ForwardBackwardSliding:
      return "forward_backward_sliding";
    case ClassicalRegime::Hopping:
      return "hopping";
  }
  return "unknown";
}

double throwNumber(const ClassicalParams& p) {
  const double w = kTwoPi * p.frequency;
  return p.amplitude * w * w * std::sin(p.vibration_angle) / (p.gravity * std::cos(p.track_angle));
}

double amplitudeForThrowNumber(const ClassicalParams& p, double gamma) {
  const double w = kTwoPi * p.frequency;
  return gamma * p.gravity * std::cos(p.track_angle) / (w * w * std::sin(p.vibration_angle));
}

double forwardOnsetThrowNumber(const ClassicalParams& p) {
  return (p.mu + std::tan(p.track_angle)) / (p.mu + 1.0 / std::tan(p.vibration_angle));
}

double backwardOnsetThrowNumber(const ClassicalParams& p) {
  const double denominator = 1.0 / std::tan(p.vibration_angle) - p.mu;
  if (!(denominator > 0)) return std::numeric_limits<double>::infinity();
  return (p.mu - std::tan(p.track_angle)) / denominator;
}

double conveyingEfficiency(const ClassicalParams& p, double mean_speed) {
  return mean_speed / (p.amplitude * kTwoPi * p.frequency * std::cos(p.vibration_angle));
}

ClassicalDrift classicalDrift(const ClassicalParams& params) {
  params.validate();
  Model model(params);
  model.start();

  const int max_cycles = params.max_cycles;
  std::vector<CycleStats> stats;
  std::vector<CycleStart> starts;
  stats.reserve(static_cast<std::size_t>(max_cycles));
  starts.reserve(static_cast<std::size_t>(max_cycles) + 1);
  starts.push_back(model.cycleStart());

  ClassicalDrift out;
  int first = 0, count = 0;  // the averaged cycles
  for (int k = 1; k <= max_cycles && count == 0; ++k) {
    stats.push_back(model.cycle(out.events));
    starts.push_back(model.cycleStart());
    out.cycles = k;
    for (int p = 1; p <= std::min(params.max_period, k); ++p) {
      if (sameStart(starts[static_cast<std::size_t>(k)], starts[static_cast<std::size_t>(k - p)],
                    params.periodic_tolerance)) {
        out.period = p;
        first = k - p;
        count = p;
        break;
      }
    }
  }
  if (count == 0) {
    count = std::min(params.average_cycles, out.cycles);
    first = out.cycles - count;
  }

  double displacement = 0, time[4] = {};
  for (int k = first; k < first + count; ++k) {
    const CycleStats& c = stats[static_cast<std::size_t>(k)];
    displacement += c.displacement;
    for (int i = 0; i < 4; ++i) time[i] += c.time[i];
  }
  const double total = count * kTwoPi;
  const double w = kTwoPi * params.frequency;
  out.mean_speed = displacement / total * params.gravity / w;  // (g / w^2) / (1 / w)
  out.stick_fraction = time[static_cast<int>(Phase::Stick)] / total;
  out.forward_slip_fraction = time[static_cast<int>(Phase::SlideUp)] / total;
  out.backward_slip_fraction = time[static_cast<int>(Phase::SlideDown)] / total;
  out.flight_fraction = time[static_cast<int>(Phase::Flight)] / total;
  out.throw_number = throwNumber(params);
  out.efficiency = conveyingEfficiency(params, out.mean_speed);
  if (out.flight_fraction > 0) {
    out.regime = ClassicalRegime::Hopping;
  } else if (out.forward_slip_fraction > 0 && out.backward_slip_fraction > 0) {
    out.regime = ClassicalRegime::ForwardBackwardSliding;
  } else if (out.forward_slip_fraction > 0) {
    out.regime = ClassicalRegime::ForwardSliding;
  } else if (out.backward_slip_fraction > 0) {
    out.regime = ClassicalRegime::BackwardSliding;
  } else {
    out.regime = ClassicalRegime::NoMotion;
  }
  return out;
}

ClassicalTrack classicalTrack(const Vibration& vibration, const Vec3& point,
                              const Vec3& track_direction, const Vec3& track_normal,
                              const Vec3& gravity, double mu) {
  auto unit = [](const char* name, const Vec3& v) {
    if (!isFinite(v) || std::abs(norm(v) - 1.0) > 1e-6) bad(name, norm(v), "must be a unit vector");
  };
  unit("track_direction length", track_direction);
  unit("track_normal length", track_normal);
  if (std::abs(dot(track_direction, track_normal)) > kOrthogonality) {
    bad("track_direction . track_normal", dot(track_direction, track_normal),
        "must be 0 (orthogonal)");
  }
  if (!isFinite(point)) bad("point.x", point.x, "point must be finite");
  if (!isFinite(gravity)) bad("gravity.z", gravity.z, "gravity must be finite");

  // First-order displacement amplitude at the point (translation and torsion are in phase).
  const Vec3 a =
      vibration.amplitude * vibration.direction +
      vibration.torsion_amplitude * cross(vibration.axis_direction, point - vibration.axis_origin);
  double a_t = dot(a, track_direction), a_n = dot(a, track_normal);
  ClassicalTrack out;
  out.lateral_amplitude = norm(a - a_t * track_direction - a_n * track_normal);
  if (a_n < 0) {  // A sin(w t) along -d is A sin(w t + pi) along d: same steady state
    a_t = -a_t;
    a_n = -a_n;
  }
  const double amplitude = std::hypot(a_t, a_n);
  if (!(a_n > 1e-12 * amplitude)) {
    bad("local vibration normal amplitude", a_n, "must be > 0 (the model needs a throw)");
  }
  if (!(std::abs(a_t) > 1e-12 * amplitude)) {
    bad("local vibration tangential amplitude", a_t, "must be != 0 (nothing drives the part)");
  }
  out.conveying_direction = a_t > 0 ? track_direction : -track_direction;
  const double g_t = dot(gravity, out.conveying_direction), g_n = dot(gravity, track_normal);
  if (!(g_n < 0)) bad("gravity . track_normal", g_n, "must be < 0 (gravity presses the part)");
  out.lateral_gravity = norm(gravity - g_t * out.conveying_direction - g_n * track_normal);

  ClassicalParams& p = out.params;
  p.track_angle = std::atan2(-g_t, -g_n);
  p.vibration_angle = std::atan2(a_n, std::abs(a_t));
  p.amplitude = amplitude;
  p.frequency = vibration.frequency;
  p.mu = mu;
  p.gravity = std::hypot(g_t, g_n);
  p.validate();
  return out;
}

}  // namespace rheofeed::scene
