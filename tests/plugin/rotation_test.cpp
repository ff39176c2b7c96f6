// SPDX-License-Identifier: MIT
// Rotation laws (MotionLaw::rotation) on whole scenes: a turntable carries parts along w x r,
// a part sticking to it stays on its circle over a long run when the step is given (the secant),
// a rotating helical ramp lifts a part when w agrees with the helix's handedness.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "ode_world.hpp"

namespace rheofeed::test {
namespace {

constexpr double kStep = 0.001;  // s
constexpr double kLayer = 1e-4;  // m, contact surface layer; parts start at this depth
// dWorldStep solves each step's LCP exactly up to CFM = 1e-9 and round-off.
constexpr double kLcpTolerance = 1e-9;

// ---------------------------------------------------------------------------------------------
// Turntable

constexpr double kTableMu = 1.0;
constexpr double kTableW = 2.0;     // rad/s about +z
constexpr double kPartSize = 0.04;  // m, cubic parts
constexpr double kPartMass = 0.1;   // kg

// Co-rotation needs a centripetal force w^2 r m from friction: w^2 r = 0.8 m/s^2 at the outer
// radius 0.2 m, far below mu g = 9.81 m/s^2, so the parts stick once they reach w r (with the
// Approx1 pyramid, fdir1 along c_t = w x r puts the radial force on the second friction row,
// bounded by mu N as well). Short runs keep the parts near their start radius.
struct Turntable {
  explicit Turntable(double angular_speed) : w(angular_speed) {
    world.setSurface(dContactApprox1, kTableMu);
    dWorldSetContactSurfaceLayer(world.world, kLayer);
    table = world.staticBox(1.2, 1.2, 0.1, 0, 0, -0.05);
    world.feeders->add(table, MotionLaw::rotation({0, 0, w}, {0, 0, 0}));
  }
  dBodyID part(double x, double y) {
    return world.box(kPartSize, kPartSize, kPartSize, kPartMass, x, y, kPartSize / 2 - kLayer);
  }
  double w;
  OdeWorld world;
  dGeomID table;
};

/// Tangential and radial speed (m/s) of a body at `p` moving at `v`, with e_phi = (-y, x)/r.
void polar(const Vec3& p, const Vec3& v, double* tangential, double* radial) {
  const double r = std::hypot(p.x, p.y);
  *tangential = (-p.y * v.x + p.x * v.y) / r;
  *radial = (p.x * v.x + p.y * v.y) / r;
}

}  // namespace

TEST(Turntable, PartsReachOmegaTimesRadiusInTheDirectionOfWCrossR) {
  Turntable t(kTableW);
  struct Part {
    dBodyID body;
    double r0;
    double reached = -1.0;
  };
  Part parts[] = {{t.part(0.1, 0.0), 0.1}, {t.part(0.0, -0.2), 0.2}};
  while (t.world.time < 0.3) {
    Vec3 before[2];
    for (int i = 0; i < 2; ++i) before[i] = position(parts[i].body);
    t.world.step(kStep);
    for (int i = 0; i < 2; ++i) {
      // Sticking on a rigidly rotating surface means moving with it: v = w x p, where p is
      // the position at the start of the step (where the contacts were made), and spinning
      // at w about z. w x p = w (-p_y, p_x, 0), counter-clockwise for w > 0.
      const Vec3 v = linearVelocity(parts[i].body);
      const Vec3 expected{-kTableW * before[i].y, kTableW * before[i].x, 0.0};
      if (parts[i].reached < 0 && norm(v - expected) < 1e-6) parts[i].reached = t.world.time;
    }
  }
  for (int i = 0; i < 2; ++i) {
    SCOPED_TRACE(testing::Message() << "part at r = " << parts[i].r0);
    // Friction mu g along e_phi from rest: w r after w r / (mu g). The part is not a point:
    // friction at its corners points along e_phi(corner), up to atan(d/r) off (d = half
    // diagonal), which slows the spin-up by up to 1 - cos = (d/r)^2 / 2; plus one step.
    const double expected = kTableW * parts[i].r0 / (kTableMu * kGravity);
    const double d = kPartSize / std::sqrt(2.0);
    const double tolerance = kStep + expected * 0.5 * (d / parts[i].r0) * (d / parts[i].r0);
    std::printf("[ measured ] turntable r = %.2f: w r reached after %.4f s, w r/(mu g) = %.4f\n",
                parts[i].r0, parts[i].reached, expected);
    EXPECT_NEAR(parts[i].reached, expected, tolerance);
  }

  // After the spin-up: co-rotation, checked step by step.
  double worst_v = 0.0, worst_w = 0.0;
  for (int k = 0; k < 100; ++k) {
    Vec3 before[2];
    for (int i = 0; i < 2; ++i) before[i] = position(parts[i].body);
    t.world.step(kStep);
    for (int i = 0; i < 2; ++i) {
      const Vec3 v = linearVelocity(parts[i].body);
      worst_v = std::fmax(worst_v, std::fabs(v.x + kTableW * before[i].y));
      worst_v = std::fmax(worst_v, std::fabs(v.y - kTableW * before[i].x));
      worst_v = std::fmax(worst_v, std::fabs(v.z));
      worst_w = std::fmax(worst_w, std::fabs(angularVelocity(parts[i].body).z - kTableW));
    }
  }
  EXPECT_LT(worst_v, kLcpTolerance);
  EXPECT_LT(worst_w, kLcpTolerance);

  // Direction and magnitude in polar terms at each part's current radius.
  for (const Part& part : parts) {
    const Vec3 p = position(part.body);
    double tangential, radial;
    polar(p, linearVelocity(part.body), &tangential, &radial);
    const double r = std::hypot(p.x, p.y);
    // v = w x p(start of step): seen from the end-of-step position, which has turned by
    // w h, v has a radial part h w^2 r and a tangential part w r (1 - O((w h)^2)).
    const double turn = kTableW * kStep;
    EXPECT_NEAR(tangential, kTableW * r, kTableW * r * turn * turn + kLcpTolerance);
    EXPECT_NEAR(radial, turn * kTableW * r, kTableW * r * turn * turn + kLcpTolerance);
    EXPECT_NEAR(r, part.r0, 0.01 * part.r0);  // stayed near its radius: no centrifugal drift
  }
}

TEST(Turntable, NegativeOmegaTurnsPartsClockwise) {
  Turntable t(-kTableW);
  dBodyID part = t.part(0.1, 0.0);
  t.world.run(0.1, kStep);
  double tangential, radial;
  polar(position(part), linearVelocity(part), &tangential, &radial);
  EXPECT_LT(tangential, 0.0);
  EXPECT_NEAR(tangential, -kTableW * std::hypot(position(part).x, position(part).y), 1e-5);
  EXPECT_NEAR(angularVelocity(part).z, -kTableW, kLcpTolerance);
}

// ---------------------------------------------------------------------------------------------
// Turntable over a long run at a large step: the secant surface velocity

namespace {

// A box sticking to a turntable (w about +z, static feeder geom) keeps its distance r to the
// axis, its polar angle advances by w t and it spins at w: rigid co-rotation. Stepping with
// h = 0.01 s for 60 s, the secant surface velocity (the step given to collide) carries its
// centre of mass along the chord to the point turned by w h each step; the instantaneous w x r
// carries it along the tangent, to a radius sqrt(1 + (w h)^2) times larger each step.
constexpr double kLongStep = 0.01;    // s
constexpr double kLongDuration = 60;  // s
constexpr double kLongRadius = 0.1;   // m, initial distance of the box's centre to the axis
// Sticking needs m w^2 r <= mu m g: w^2 r = 2.5 m/s^2 at w = 5 rad/s, r = 0.1 m.
constexpr double kLongMu = 1.0;
// The requirement for a sticking part: radius constant to 1e-6 relative over 60 s.
// What remains is CFM's creep: the four contacts share the centripetal force m w^2 r and each
// slips outwards at cfm m w^2 r / 4, r0 cfm m w^2 t / 4 = 3.75e-8 r0 at w = 5 rad/s (measured).
constexpr double kRadiusTolerance = 1e-6;  // relative
// dWorldStep solves each LCP exactly up to CFM 1e-9 (tests/support/ode_world.hpp): the same
// budget as the radius for the arc, 1e-6 r.
constexpr double kAngleTolerance = 1e-6;  // rad
constexpr double kSpinTolerance = 1e-6;   // rad/s

struct LongRun {
  double worst_radius_error = 0;  // max |r - r0| / r0 over the run
  double final_radius_ratio = 1;  // r / r0 at the end
  double angle_error = 0;         // unwrapped polar angle - w t at the end (rad)
  double spin = 0;                // angular velocity z at the end (rad/s)
  int steps = 0;
  bool finite = true;
};

// `step_given` is what the application passes to ContactCollider::collide: h, or 0 for the
// instantaneous field.
LongRun runLongTurntable(double w, double step_given) {
  OdeWorld world;
  world.setSurface(dContactApprox1, kLongMu);
  dWorldSetContactSurfaceLayer(world.world, kLayer);
  const dGeomID table = world.staticBox(1.2, 1.2, 0.1, 0, 0, -0.05);
  world.feeders->add(table, MotionLaw::rotation({0, 0, w}, {0, 0, 0}));
  // Starts co-rotating and kLayer deep (in contact), so it sticks from the first step on.
  dBodyID box =
      world.box(kPartSize, kPartSize, kPartSize, kPartMass, kLongRadius, 0, kPartSize / 2 - kLayer);
  dBodySetLinearVel(box, 0, w * kLongRadius, 0);
  dBodySetAngularVel(box, 0, 0, w);

  LongRun run;
  run.steps = static_cast<int>(kLongDuration / kLongStep + 0.5);
  double angle = 0, previous = 0;
  for (int i = 0; i < run.steps; ++i) {
    world.collider->collide(world.space, world.time, step_given);
    dWorldStep(world.world, kLongStep);
    world.time += kLongStep;
    const Vec3 p = position(box);
    if (!isFinite(p)) {
      run.finite = false;
      return run;
    }
    const double a = std::atan2(p.y, p.x);
    angle += std::remainder(a - previous, 2 * kPi);  // turns of w h << pi per step
    previous = a;
    run.final_radius_ratio = std::hypot(p.x, p.y) / kLongRadius;
    run.worst_radius_error =
        std::fmax(run.worst_radius_error, std::fabs(run.final_radius_ratio - 1));
  }
  run.angle_error = angle - w * world.time;
  run.spin = angularVelocity(box).z;
  std::printf(
      "[ measured ] ODE turntable w = %g rad/s, h = %g s, step given %g s, %g s: max "
      "|r - r0|/r0 = %.3g, r/r0 = %.9f, angle - w t = %.3g rad, spin - w = %.3g rad/s\n",
      w, kLongStep, step_given, world.time, run.worst_radius_error, run.final_radius_ratio,
      run.angle_error, run.spin - w);
  return run;
}

}  // namespace

TEST(TurntableSecant, StickingBoxStaysOnItsCircleAtOneRadPerSecond) {
  const LongRun run = runLongTurntable(1.0, kLongStep);
  ASSERT_TRUE(run.finite);
  EXPECT_LT(run.worst_radius_error, kRadiusTolerance);
  EXPECT_NEAR(run.angle_error, 0.0, kAngleTolerance);
  EXPECT_NEAR(run.spin, 1.0, kSpinTolerance);
}

TEST(TurntableSecant, StickingBoxStaysOnItsCircleAtFiveRadPerSecond) {
  const LongRun run = runLongTurntable(5.0, kLongStep);
  ASSERT_TRUE(run.finite);
  EXPECT_LT(run.worst_radius_error, kRadiusTolerance);
  EXPECT_NEAR(run.angle_error, 0.0, kAngleTolerance);
  EXPECT_NEAR(run.spin, 5.0, kSpinTolerance);
}

// Documented behaviour without the step (step = 0): each step moves the sticking box along the
// tangent by w r h, to radius r sqrt(1 + (w h)^2) and polar angle + atan(w h). After n steps
// r / r0 = (1 + (w h)^2)^(n/2) (1.3498 here) and the angle lags w t by n (w h - atan(w h)).
TEST(TurntableSecant, WithoutTheStepTheBoxSpiralsOutwardsAlongTheTangent) {
  constexpr double kW = 1.0;
  const LongRun run = runLongTurntable(kW, 0.0);
  ASSERT_TRUE(run.finite);
  const double turn = kW * kLongStep;
  const double expected_ratio = std::pow(1.0 + turn * turn, 0.5 * run.steps);
  EXPECT_NEAR(run.final_radius_ratio, expected_ratio, kRadiusTolerance * expected_ratio);
  EXPECT_NEAR(run.angle_error, -run.steps * (turn - std::atan(turn)), kAngleTolerance);
  EXPECT_GT(run.worst_radius_error, 0.3);  // far outside the secant's tolerance
}

// ---------------------------------------------------------------------------------------------
// Helical ramp

namespace {

constexpr double kHelixRadius = 0.3;  // m, centre line of the track
constexpr double kHelixPitch = 0.1;   // m of rise per turn (right-handed if > 0)
constexpr double kHelixWidth = 0.1;   // m, radial width of the track
constexpr double kHelixThickness = 0.02;
constexpr double kSegmentAngle = 3.0 * kPi / 180.0;  // rad per flat segment
constexpr double kHelixMu = 0.5;
constexpr double kHelixW = 1.0;  // rad/s

/// A helical ramp z = pitch * phi / (2 pi) around the z axis at radius kHelixRadius, made of
/// flat static box segments (chords of kSegmentAngle, slightly overlapping), every segment a
/// feeder with the rotation law w about z. pitch > 0: right-handed, rising counter-clockwise
/// seen from above. A small box part starts on the track at phi = 0.
struct HelixRamp {
  HelixRamp(double rise_per_turn, double w) : pitch(rise_per_turn) {
    world.setSurface(dContactApprox1, kHelixMu);
    dWorldSetContactSurfaceLayer(world.world, kLayer);
    slope = std::atan(pitch / (2 * kPi * kHelixRadius));  // signed slope along +phi
    const double chord = 2 * kHelixRadius * std::tan(kSegmentAngle / 2) * 1.05;
    for (double phi = -200 * kPi / 180; phi <= 200 * kPi / 180 + 1e-9; phi += kSegmentAngle) {
      dGeomID g = dCreateBox(world.space, chord / std::cos(slope), kHelixWidth, kHelixThickness);
      dMatrix3 r;
      orientation(phi, r);
      dGeomSetRotation(g, r);
      const Vec3 top = trackPoint(phi);
      const Vec3 n = normal(phi);
      dGeomSetPosition(g, top.x - kHelixThickness / 2 * n.x, top.y - kHelixThickness / 2 * n.y,
                       top.z - kHelixThickness / 2 * n.z);
      world.feeders->add(g, MotionLaw::rotation({0, 0, w}, {0, 0, 0}));
    }
    part = world.box(0.03, 0.03, kPartHeight, 0.05, 0, 0, 0);
    dMatrix3 r;
    orientation(0.0, r);
    dBodySetRotation(part, r);
    const Vec3 n = normal(0.0);
    const double lift = kPartHeight / 2 + 0.0005;  // dropped from 0.5 mm
    const Vec3 p = trackPoint(0.0) + lift * n;
    dBodySetPosition(part, p.x, p.y, p.z);
  }
  Vec3 trackPoint(double phi) const {
    return {kHelixRadius * std::cos(phi), kHelixRadius * std::sin(phi), pitch * phi / (2 * kPi)};
  }
  // Segment frame: x along the track (rising with phi if pitch > 0), y inward, z the normal.
  Vec3 along(double phi) const {
    return {-std::cos(slope) * std::sin(phi), std::cos(slope) * std::cos(phi), std::sin(slope)};
  }
  Vec3 normal(double phi) const {
    return {std::sin(slope) * std::sin(phi), -std::sin(slope) * std::cos(phi), std::cos(slope)};
  }
  void orientation(double phi, dMatrix3 r) const {
    const Vec3 x = along(phi);
    dRFrom2Axes(r, x.x, x.y, x.z, -std::cos(phi), -std::sin(phi), 0);
  }
  /// Rise rate (m/s) of a part moving with the surface: the tangential part of w x p on the
  /// track is w R cos(slope) along the track, whose vertical part is w R cos sin.
  double expectedRiseRate(double w) const {
    return w * kHelixRadius * std::cos(slope) * std::sin(slope);
  }

  static constexpr double kPartHeight = 0.015;
  double pitch;
  double slope;
  OdeWorld world;
  dBodyID part;
};

// The part crosses a seam between flat chord segments every 3 degrees (about 6 per 100 ms) and
// drifts outward by ~1 % of R; the mean rise rate over 1.8 s stays within a few percent.
constexpr double kRiseRateTolerance = 0.03;  // relative

/// Mean rise rate (m/s) of the ramp's part from 0.1 s (landed, spun up) to 1.9 s.
double measuredRiseRate(HelixRamp& ramp) {
  ramp.world.run(0.1, kStep);
  const double z0 = position(ramp.part).z;
  const double t0 = ramp.world.time;
  ramp.world.run(1.8, kStep);
  return (position(ramp.part).z - z0) / (ramp.world.time - t0);
}

}  // namespace

TEST(HelicalRamp, RightHandedHelixIsClimbedWithPositiveOmega) {
  HelixRamp ramp(kHelixPitch, kHelixW);
  const double rate = measuredRiseRate(ramp);
  std::printf("[ measured ] helix climb: %.5f m/s, w R cos sin = %.5f m/s\n", rate,
              ramp.expectedRiseRate(kHelixW));
  EXPECT_GT(rate, 0.0);
  EXPECT_NEAR(rate, ramp.expectedRiseRate(kHelixW),
              kRiseRateTolerance * std::fabs(ramp.expectedRiseRate(kHelixW)));
}

TEST(HelicalRamp, RightHandedHelixIsDescendedWithNegativeOmega) {
  HelixRamp ramp(kHelixPitch, -kHelixW);
  const double rate = measuredRiseRate(ramp);
  EXPECT_LT(rate, 0.0);
  EXPECT_NEAR(rate, ramp.expectedRiseRate(-kHelixW),
              kRiseRateTolerance * std::fabs(ramp.expectedRiseRate(kHelixW)));
}

TEST(HelicalRamp, LeftHandedHelixIsClimbedWithNegativeOmega) {
  HelixRamp ramp(-kHelixPitch, -kHelixW);
  const double rate = measuredRiseRate(ramp);
  EXPECT_GT(rate, 0.0);
  EXPECT_NEAR(rate, ramp.expectedRiseRate(-kHelixW),
              kRiseRateTolerance * std::fabs(ramp.expectedRiseRate(kHelixW)));
}

TEST(HelicalRamp, LeftHandedHelixIsDescendedWithPositiveOmega) {
  HelixRamp ramp(-kHelixPitch, kHelixW);
  const double rate = measuredRiseRate(ramp);
  EXPECT_LT(rate, 0.0);
}

}  // namespace rheofeed::test
