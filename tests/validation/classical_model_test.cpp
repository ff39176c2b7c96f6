// SPDX-License-Identifier: MIT
// The classical single-part model (classical_model.hpp) against closed forms derived here,
// independently of the model's event machinery:
// - the onset throw numbers, found by bisection on the model's regime, against the formulas
//   of Redford & Boothroyd (NOTES section 5);
// - the mean speed of forward sliding with sticking, from one slide per cycle integrated by
//   Simpson's rule;
// - the mean speed of a hop with unbounded friction (stick before lift-off, stick at
//   landing), from the projectile flight;
// - the mean speed of the hop that lasts exactly one cycle, pi g cot(beta) / w;
// - the 1/f scaling at fixed throw number, the efficiency, the input checks, and the local
//   parameters of a vibrating feeder (classicalTrack).
#include "rheofeed/measure/classical_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

namespace rheofeed::scene {
namespace {

constexpr double kDeg = kPi / 180;
constexpr double kG = 9.81;

// The model locates events to rounding; a bisection on its regime flags recovers a threshold
// to the bisection's width (1e-12) times the slope of the regime boundary.
constexpr double kThresholdTolerance = 1e-9;  // throw number
// Both the model and the integral below are exact up to root finding (1e-12 rad) and Simpson's
// rule (10^4 intervals on a smooth integrand: ~1e-14 relative).
constexpr double kSlideSpeedTolerance = 1e-8;  // relative
// With mu = 1e4 the part slips for a phase O(cot(beta) / mu) before lift-off and can keep a
// tangential velocity O(1 / mu) at landing: the unbounded-friction limit holds to ~1e-4.
constexpr double kHighFrictionTolerance = 1e-3;  // relative
// The one-cycle hop is an exact periodic orbit of the model.
constexpr double kOneCycleHopTolerance = 1e-9;  // relative
// The model is dimensionless in w t, g / w and g / w^2: the 1/f law is exact up to rounding.
constexpr double kScalingTolerance = 1e-9;  // relative

ClassicalParams params(double gamma, double track_angle = 0, double vibration_angle = 30 * kDeg,
                       double mu = 0.5, double frequency = 50) {
  ClassicalParams p;
  p.track_angle = track_angle;
  p.vibration_angle = vibration_angle;
  p.mu = mu;
  p.frequency = frequency;
  p.gravity = kG;
  p.amplitude = gamma * kG * std::cos(track_angle) /
                (std::pow(2 * kPi * frequency, 2) * std::sin(vibration_angle));
  return p;
}

// Smallest throw number in (lo, hi) at which `happens` becomes true, by bisection.
double bisectThrow(ClassicalParams p, double lo, double hi,
                   const std::function<bool(const ClassicalDrift&)>& happens) {
  auto at = [&](double gamma) {
    p.amplitude = params(gamma, p.track_angle, p.vibration_angle, p.mu, p.frequency).amplitude;
    return happens(classicalDrift(p));
  };
  EXPECT_FALSE(at(lo)) << "gamma " << lo;
  EXPECT_TRUE(at(hi)) << "gamma " << hi;
  while (hi - lo > 1e-12) {
    const double mid = 0.5 * (lo + hi);
    (at(mid) ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

// The first root after `from` of f, scanning by `step` then bisecting.
double firstRoot(const std::function<double(double)>& f, double from, double step, double to) {
  double a = from + step;
  const bool positive = f(a) > 0;
  for (double b = a + step; b <= to; a = b, b += step) {
    if ((f(b) > 0) != positive) {
      for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (a + b);
        ((f(mid) > 0) == positive ? a : b) = mid;
      }
      return 0.5 * (a + b);
    }
  }
  ADD_FAILURE() << "no root in (" << from << ", " << to << ")";
  return to;
}

struct Geometry {
  double alpha, beta, mu;
};

TEST(ClassicalModel, ForwardSlidingStartsAtRedfordBoothroydThreshold) {
  for (const Geometry& g :
       {Geometry{0, 30 * kDeg, 0.5}, Geometry{3 * kDeg, 25 * kDeg, 0.5},
        Geometry{-2 * kDeg, 25 * kDeg, 0.8}, Geometry{5 * kDeg, 35 * kDeg, 1.0}}) {
    const double expected = (g.mu + std::tan(g.alpha)) / (g.mu + 1 / std::tan(g.beta));
    SCOPED_TRACE("alpha " + std::to_string(g.alpha) + " beta " + std::to_string(g.beta));
    const ClassicalParams p = params(0.5, g.alpha, g.beta, g.mu);
    EXPECT_NEAR(forwardOnsetThrowNumber(p), expected, 1e-15);
    const double found =
        bisectThrow(p, 0.5 * expected, std::min(1.5 * expected, 0.999),
                    [](const ClassicalDrift& d) { return d.forward_slip_fraction > 0; });
    EXPECT_NEAR(found, expected, kThresholdTolerance);
    // Below it the part does not move at all; above it it conveys up-track.
    ClassicalParams below = params(0.99 * expected, g.alpha, g.beta, g.mu);
    EXPECT_EQ(classicalDrift(below).regime, ClassicalRegime::NoMotion);
    EXPECT_EQ(classicalDrift(below).mean_speed, 0.0);
    EXPECT_GT(classicalDrift(params(1.01 * expected, g.alpha, g.beta, g.mu)).mean_speed, 0.0);
  }
}

// Steep tracks (Gamma_b < Gamma_f): the part already slides down-track once per cycle, yet it
// is back at rest when a - mu N peaks, so up-track sliding still starts at Gamma_f.
TEST(ClassicalModel, ForwardSlidingStartsAtThresholdAlsoAfterBackwardSliding) {
  for (const Geometry& g :
       {Geometry{3 * kDeg, 20 * kDeg, 0.3}, Geometry{15 * kDeg, 30 * kDeg, 0.5}}) {
    const double expected = (g.mu + std::tan(g.alpha)) / (g.mu + 1 / std::tan(g.beta));
    const double backward = (g.mu - std::tan(g.alpha)) / (1 / std::tan(g.beta) - g.mu);
    ASSERT_LT(backward, expected);
    const double found = bisectThrow(
        params(0.5, g.alpha, g.beta, g.mu), 0.5 * expected, std::min(1.5 * expected, 0.999),
        [](const ClassicalDrift& d) { return d.forward_slip_fraction > 0; });
    EXPECT_NEAR(found, expected, kThresholdTolerance) << "alpha " << g.alpha;
  }
}

TEST(ClassicalModel, BackwardSlidingStartsAtRedfordBoothroydThreshold) {
  // Including a steep track (alpha = 15 deg) where backward sliding starts first.
  for (const Geometry& g : {Geometry{0, 30 * kDeg, 0.5}, Geometry{3 * kDeg, 20 * kDeg, 0.3},
                            Geometry{15 * kDeg, 30 * kDeg, 0.5}}) {
    const double expected = (g.mu - std::tan(g.alpha)) / (1 / std::tan(g.beta) - g.mu);
    SCOPED_TRACE("alpha " + std::to_string(g.alpha) + " beta " + std::to_string(g.beta));
    ASSERT_LT(expected, 1.0);
    const ClassicalParams p = params(0.5, g.alpha, g.beta, g.mu);
    EXPECT_NEAR(backwardOnsetThrowNumber(p), expected, 1e-15);
    const double found =
        bisectThrow(p, 0.5 * expected, std::min(1.5 * expected, 0.999),
                    [](const ClassicalDrift& d) { return d.backward_slip_fraction > 0; });
    EXPECT_NEAR(found, expected, kThresholdTolerance);
  }
}

TEST(ClassicalModel, SteepTrackSlidesBackOnlyBetweenTheTwoThresholds) {
  const double alpha = 15 * kDeg, beta = 30 * kDeg, mu = 0.5;
  const ClassicalParams p = params(0.3, alpha, beta, mu);
  ASSERT_LT(backwardOnsetThrowNumber(p), 0.3);
  ASSERT_GT(forwardOnsetThrowNumber(p), 0.3);
  const ClassicalDrift d = classicalDrift(p);
  EXPECT_EQ(d.regime, ClassicalRegime::BackwardSliding);
  EXPECT_LT(d.mean_speed, 0.0);
  EXPECT_EQ(d.forward_slip_fraction, 0.0);
}

TEST(ClassicalModel, NoBackwardSlidingWhenCotBetaIsBelowMu) {
  const ClassicalParams p = params(0.99, 0, 65 * kDeg, 0.5);  // cot(65 deg) = 0.466 < 0.5
  EXPECT_TRUE(std::isinf(backwardOnsetThrowNumber(p)));
  const ClassicalDrift d = classicalDrift(p);
  EXPECT_EQ(d.backward_slip_fraction, 0.0);
  EXPECT_EQ(d.regime, ClassicalRegime::ForwardSliding);
}

TEST(ClassicalModel, HopsExactlyAboveThrowNumberOne) {
  for (const Geometry& g : {Geometry{0, 30 * kDeg, 0.5}, Geometry{4 * kDeg, 20 * kDeg, 0.4}}) {
    SCOPED_TRACE("alpha " + std::to_string(g.alpha));
    const ClassicalDrift below = classicalDrift(params(0.999, g.alpha, g.beta, g.mu));
    const ClassicalDrift above = classicalDrift(params(1.001, g.alpha, g.beta, g.mu));
    EXPECT_NE(below.regime, ClassicalRegime::Hopping);
    EXPECT_EQ(below.flight_fraction, 0.0);
    EXPECT_EQ(above.regime, ClassicalRegime::Hopping);
    EXPECT_GT(above.flight_fraction, 0.0);
    EXPECT_NEAR(above.throw_number, 1.001, 1e-12);
    const double found =
        bisectThrow(params(1, g.alpha, g.beta, g.mu), 0.9, 1.1,
                    [](const ClassicalDrift& d) { return d.regime == ClassicalRegime::Hopping; });
    EXPECT_NEAR(found, kHoppingOnsetThrowNumber, kThresholdTolerance);
  }
}

// Forward sliding only (Gamma_f < Gamma < Gamma_b, Gamma < 1): the part sticks until
// a - mu N = P + Q sin(phi) turns positive at phi1 = asin(-P / Q) (units of g, phase phi = w t),
// slides with u(phi) = P (phi - phi1) - Q (cos(phi) - cos(phi1)) (units g / w) until u = 0 at
// phi2, and sticks again. Mean speed = (g / w) / (2 pi) * integral of u over [phi1, phi2].
TEST(ClassicalModel, ForwardSlidingSpeedMatchesTheSlideIntegral) {
  for (const Geometry& g : {Geometry{0, 30 * kDeg, 0.5}, Geometry{3 * kDeg, 25 * kDeg, 0.5}}) {
    const ClassicalParams probe = params(0.5, g.alpha, g.beta, g.mu);
    const double gf = forwardOnsetThrowNumber(probe), gb = backwardOnsetThrowNumber(probe);
    for (double t : {0.1, 0.5, 0.95}) {
      const double gamma = gf + t * (std::min(gb, 1.0) - gf);
      const ClassicalParams p = params(gamma, g.alpha, g.beta, g.mu, 60);
      const double w = 2 * kPi * p.frequency, aw2 = p.amplitude * w * w / kG;
      const double P = -std::sin(g.alpha) - g.mu * std::cos(g.alpha);
      const double Q = aw2 * (std::cos(g.beta) + g.mu * std::sin(g.beta));
      const double phi1 = std::asin(-P / Q);
      auto u = [&](double phi) { return P * (phi - phi1) - Q * (std::cos(phi) - std::cos(phi1)); };
      const double phi2 = firstRoot(u, phi1, 1e-3, phi1 + 2 * kPi);
      const int n = 10000;  // Simpson
      const double hs = (phi2 - phi1) / n;
      double sum = u(phi1) + u(phi2);
      for (int i = 1; i < n; ++i) sum += (i % 2 ? 4 : 2) * u(phi1 + i * hs);
      const double expected = (kG / w) * (sum * hs / 3) / (2 * kPi);

      const ClassicalDrift d = classicalDrift(p);
      SCOPED_TRACE("gamma " + std::to_string(gamma));
      EXPECT_EQ(d.regime, ClassicalRegime::ForwardSliding);
      EXPECT_NEAR(d.mean_speed, expected, kSlideSpeedTolerance * expected);
      EXPECT_NEAR(d.forward_slip_fraction, (phi2 - phi1) / (2 * kPi), 1e-9);
      EXPECT_EQ(d.period, 1);
    }
  }
}

// Unbounded friction, horizontal track: the part moves with the track until lift-off at
// sin(phi_l) = 1 / Gamma, flies, and sticks at landing. In flight, relative to the track,
// x'' = A w^2 cos(beta) sin(w t) and y'' = -g + A w^2 sin(beta) sin(w t) from rest, so
// y + g tau^2 / 2 = tan(beta) x: at landing (y = 0) x = cot(beta) g tau^2 / 2 per cycle.
TEST(ClassicalModel, HopWithUnboundedFrictionMovesByTheProjectileFlight) {
  for (double gamma : {1.5, 2.0, 2.5}) {
    ClassicalParams p = params(gamma, 0, 30 * kDeg, 1e4);
    const double w = 2 * kPi * p.frequency, beta = p.vibration_angle;
    const double phil = std::asin(1 / gamma);
    // y in units g / w^2 as a function of the phase
    auto y = [&](double phi) {
      const double tau = phi - phil;
      return -0.5 * tau * tau + gamma * (tau * std::cos(phil) - std::sin(phi) + std::sin(phil));
    };
    const double land = firstRoot(y, phil, 1e-3, phil + 2 * kPi);
    ASSERT_LT(std::sin(land), 1 / gamma) << "lands where the normal force is positive";
    const double tau = land - phil;  // rad
    const double expected = (kG / w) * (0.5 * tau * tau / std::tan(beta)) / (2 * kPi);

    const ClassicalDrift d = classicalDrift(p);
    SCOPED_TRACE("gamma " + std::to_string(gamma));
    EXPECT_EQ(d.regime, ClassicalRegime::Hopping);
    EXPECT_NEAR(d.mean_speed, expected, kHighFrictionTolerance * expected);
    EXPECT_NEAR(d.flight_fraction, tau / (2 * kPi), kHighFrictionTolerance);
  }
}

// A hop that lasts exactly one cycle, landing where the normal force is negative (so the part
// leaves again at once) and stopping tangentially at landing: periodicity of the normal flight
// from rest relative to the track, y(2 pi) = -2 pi^2 + 2 pi Gamma cos(phi) = 0 (alpha = 0,
// units g / w^2), gives cos(phi) = pi / Gamma, and the part's velocity along the track, constant
// in flight, is the track's at that phase: A w cos(beta) cos(phi) = pi g cot(beta) / w.
TEST(ClassicalModel, OneCycleHopMovesAtPiGCotBetaOverOmega) {
  for (double f : {50.0, 120.0}) {
    const ClassicalParams p = params(3.4, 0, 30 * kDeg, 0.5, f);
    const double w = 2 * kPi * f;
    const ClassicalDrift d = classicalDrift(p);
    const double expected = kPi * kG / std::tan(p.vibration_angle) / w;
    EXPECT_EQ(d.regime, ClassicalRegime::Hopping);
    EXPECT_EQ(d.flight_fraction, 1.0);
    EXPECT_EQ(d.period, 1);
    EXPECT_NEAR(d.mean_speed, expected, kOneCycleHopTolerance * expected);
  }
}

TEST(ClassicalModel, SpeedScalesAsOneOverFrequencyAtFixedThrowNumber) {
  for (double gamma : {0.3, 0.6, 0.9, 1.5, 2.5}) {
    const ClassicalDrift d1 = classicalDrift(params(gamma, 2 * kDeg, 25 * kDeg, 0.4, 50));
    const ClassicalDrift d2 = classicalDrift(params(gamma, 2 * kDeg, 25 * kDeg, 0.4, 100));
    SCOPED_TRACE("gamma " + std::to_string(gamma));
    EXPECT_NEAR(d2.mean_speed, 0.5 * d1.mean_speed, kScalingTolerance * std::abs(d1.mean_speed));
    EXPECT_EQ(d1.regime, d2.regime);
    EXPECT_NEAR(d1.efficiency, d2.efficiency, kScalingTolerance);
  }
}

TEST(ClassicalModel, EfficiencyIsSpeedOverPeakTrackVelocityAlongTheTrack) {
  const ClassicalParams p = params(0.7);
  const ClassicalDrift d = classicalDrift(p);
  const double peak = p.amplitude * 2 * kPi * p.frequency * std::cos(p.vibration_angle);
  EXPECT_DOUBLE_EQ(d.efficiency, d.mean_speed / peak);
  EXPECT_DOUBLE_EQ(conveyingEfficiency(p, d.mean_speed), d.efficiency);
  EXPECT_GT(d.efficiency, 0.0);
  EXPECT_LT(d.efficiency, 1.0);
}

TEST(ClassicalModel, ThrowNumberAndAmplitudeAreInverse) {
  const ClassicalParams p = params(0.8, 4 * kDeg, 25 * kDeg);
  const double w = 2 * kPi * p.frequency;
  EXPECT_NEAR(throwNumber(p),
              p.amplitude * w * w * std::sin(p.vibration_angle) / (kG * std::cos(p.track_angle)),
              1e-14);
  EXPECT_NEAR(throwNumber(p), 0.8, 1e-14);
  EXPECT_NEAR(amplitudeForThrowNumber(p, 0.8), p.amplitude, 1e-18);
}

TEST(ClassicalModel, TimeFractionsSumToOne) {
  for (double gamma : {0.1, 0.3, 0.6, 1.2, 3.0}) {
    const ClassicalDrift d = classicalDrift(params(gamma));
    EXPECT_NEAR(
        d.flight_fraction + d.forward_slip_fraction + d.backward_slip_fraction + d.stick_fraction,
        1.0, 1e-12);
    EXPECT_GT(d.period, 0) << "gamma " << gamma;  // periodic in these cases
  }
}

void expectRejected(const ClassicalParams& p, const std::string& name) {
  try {
    classicalDrift(p);
    ADD_FAILURE() << name << ": accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
  }
}

TEST(ClassicalModel, RejectsBadParametersNamingThem) {
  const ClassicalParams ok = params(0.5);
  EXPECT_NO_THROW(ok.validate());
  ClassicalParams p = ok;
  p.mu = 0;
  expectRejected(p, "mu");
  p = ok;
  p.mu = std::nan("");
  expectRejected(p, "mu");
  p = ok;
  p.track_angle = std::atan(0.6);  // tan(alpha) > mu: slides away without vibration
  expectRejected(p, "track_angle");
  p = ok;
  p.vibration_angle = 0;
  expectRejected(p, "vibration_angle");
  p = ok;
  p.vibration_angle = 0.5 * kPi;
  expectRejected(p, "vibration_angle");
  p = ok;
  p.amplitude = -1e-4;
  expectRejected(p, "amplitude");
  p = ok;
  p.frequency = 0;
  expectRejected(p, "frequency");
  p = ok;
  p.gravity = -9.81;
  expectRejected(p, "gravity");
  p = ok;
  p.max_cycles = 1;
  expectRejected(p, "max_cycles");
  p = ok;
  p.average_cycles = p.max_cycles + 1;
  expectRejected(p, "average_cycles");
  p = ok;
  p.max_period = 0;
  expectRejected(p, "max_period");
  p = ok;
  p.periodic_tolerance = 0;
  expectRejected(p, "periodic_tolerance");
}

TEST(ClassicalTrack, RecoversAnglesOfALinearFeeder) {
  const double alpha = 3 * kDeg, beta = 25 * kDeg, a = 2e-4;
  Vibration v;
  v.amplitude = a;
  v.frequency = 60;
  v.direction = {std::cos(beta), 0, std::sin(beta)};
  const Vec3 gravity{-kG * std::sin(alpha), 0, -kG * std::cos(alpha)};  // +x climbs
  const ClassicalTrack t = classicalTrack(v, {0.1, 0, 0}, {1, 0, 0}, {0, 0, 1}, gravity, 0.5);
  EXPECT_NEAR(t.params.track_angle, alpha, 1e-14);
  EXPECT_NEAR(t.params.vibration_angle, beta, 1e-14);
  EXPECT_NEAR(t.params.amplitude, a, 1e-18);
  EXPECT_NEAR(t.params.gravity, kG, 1e-14);
  EXPECT_EQ(t.params.frequency, 60.0);
  EXPECT_EQ(t.params.mu, 0.5);
  EXPECT_EQ(t.conveying_direction, (Vec3{1, 0, 0}));
  EXPECT_NEAR(t.lateral_amplitude, 0, 1e-18);
  EXPECT_NEAR(t.lateral_gravity, 0, 1e-14);

  // The opposite direction is the same vibration half a period later.
  v.direction = -v.direction;
  const ClassicalTrack same = classicalTrack(v, {0.1, 0, 0}, {1, 0, 0}, {0, 0, 1}, gravity, 0.5);
  EXPECT_NEAR(same.params.vibration_angle, beta, 1e-14);
  EXPECT_EQ(same.conveying_direction, (Vec3{1, 0, 0}));

  // Mirrored: it conveys towards -x, which descends.
  v.direction = {-std::cos(beta), 0, std::sin(beta)};
  const ClassicalTrack back = classicalTrack(v, {0.1, 0, 0}, {1, 0, 0}, {0, 0, 1}, gravity, 0.5);
  EXPECT_EQ(back.conveying_direction, (Vec3{-1, 0, 0}));
  EXPECT_NEAR(back.params.track_angle, -alpha, 1e-14);
  EXPECT_NEAR(back.params.vibration_angle, beta, 1e-14);
}

TEST(ClassicalTrack, TorsionOfABowlGivesATangentialComponent) {
  // Screw motion about +z: vertical a_z and torsion theta. At radius r on the x axis the local
  // displacement is a_z z + theta r y, so beta = atan(a_z / (theta r)) along +y.
  const double a_z = 1e-4, theta = 1e-3, r = 0.2;
  Vibration v;
  v.amplitude = a_z;
  v.direction = {0, 0, 1};
  v.torsion_amplitude = theta;
  v.frequency = 100;
  const ClassicalTrack t = classicalTrack(v, {r, 0, 0.05}, {0, 1, 0}, {0, 0, 1}, {0, 0, -kG}, 0.4);
  EXPECT_NEAR(t.params.vibration_angle, std::atan2(a_z, theta * r), 1e-12);
  EXPECT_NEAR(t.params.amplitude, std::hypot(a_z, theta * r), 1e-16);
  EXPECT_NEAR(t.params.track_angle, 0, 1e-14);
  EXPECT_EQ(t.conveying_direction, (Vec3{0, 1, 0}));
}

TEST(ClassicalTrack, RefusesWhatThePlanarModelCannotDescribe) {
  Vibration v;
  v.amplitude = 1e-4;
  v.frequency = 50;
  v.direction = {std::cos(0.5), 0, std::sin(0.5)};
  const Vec3 down{0, 0, -kG};
  EXPECT_THROW(classicalTrack(v, {}, {1, 0, 0}, {0.1, 0, 1}, down, 0.5), std::invalid_argument);
  EXPECT_THROW(classicalTrack(v, {}, {1, 0, 0}, {0, 0, 1}, -down, 0.5), std::invalid_argument);
  v.direction = {0, 0, 1};  // no tangential drive
  EXPECT_THROW(classicalTrack(v, {}, {1, 0, 0}, {0, 0, 1}, down, 0.5), std::invalid_argument);
  v.direction = {1, 0, 0};  // no throw
  EXPECT_THROW(classicalTrack(v, {}, {1, 0, 0}, {0, 0, 1}, down, 0.5), std::invalid_argument);
}

}  // namespace
}  // namespace rheofeed::scene
