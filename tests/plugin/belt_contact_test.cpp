// SPDX-License-Identifier: MIT
// Belt contacts against analytic mechanics: a box on a belt of speed V is accelerated by
// Coulomb friction at mu g until it moves at V (after V / (mu g)), then sticks; on an incline
// it sticks iff tan(theta) <= mu; a part spanning two belts turns.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "ode_world.hpp"

namespace rheofeed::test {
namespace {

constexpr double kStep = 0.001;  // s
constexpr double kMu = 0.4;
constexpr double kSpeed = 0.3;          // m/s
constexpr double kPart = 0.1;           // m, edge of the cubic part
constexpr double kMass = 1.0;           // kg
constexpr double kBeltThickness = 0.1;  // m
// ODE keeps this much penetration without pushing out (dWorldSetContactSurfaceLayer); parts
// start at exactly this depth, so they start at rest in resting contact.
constexpr double kLayer = 1e-4;  // m

// Semi-implicit Euler adds mu g h to the speed per step and the LCP stops it exactly at V in
// the step that contains t* = V / (mu g): the measured time lies in [t*, t* + h].
constexpr double kTimeTolerance = kStep;
// dWorldStep solves each step's LCP exactly up to CFM = 1e-9 and round-off.
constexpr double kLcpTolerance = 1e-9;
// "Reached" the belt speed: within this of it (m/s); far below one step's change mu g h.
constexpr double kReached = 1e-6;
// While the part sticks, CFM = 1e-9 lets each corner's normal row yield CFM * lambda (about
// 2.5e-9 m/s at 2.5 N per corner). When friction drops from mu m g to 0 at the switch to
// sticking, the corner loads that balanced its moment shift, and the part pitches at ~2e-8
// rad/s for a few steps (ERP decays it). A slipping part would be off by mu g h = 4e-3 m/s.
constexpr double kStickCreep = 5e-8;  // m/s and rad/s

/// A static belt (top face at z = 0, long along x) and a cubic part resting on it at x = x0.
struct FlatBelt {
  explicit FlatBelt(const MotionLaw& law, double x0 = 0.0, double mu = kMu) {
    w.setSurface(dContactApprox1, mu);
    dWorldSetContactSurfaceLayer(w.world, kLayer);
    belt = w.staticBox(4.0, 1.0, kBeltThickness, 0, 0, -kBeltThickness / 2);
    part = w.box(kPart, kPart, kPart, kMass, x0, 0, kPart / 2 - kLayer);
    w.feeders->add(belt, law);
  }
  OdeWorld w;
  dGeomID belt;
  dBodyID part;
};

/// A static belt inclined by `theta` (rad) so that its surface rises along +x, with a cubic
/// part resting on it (same orientation). The incline's unit direction is (cos, 0, sin).
struct InclinedBelt {
  InclinedBelt(double incline, double speed) : theta(incline) {
    w.setSurface(dContactApprox1, kMu);
    dWorldSetContactSurfaceLayer(w.world, kLayer);
    // Turning by -theta about +y maps x to (cos, 0, sin) and z to the normal (-sin, 0, cos).
    belt = w.staticBox(4.0, 1.0, kBeltThickness, 0, 0, 0, 0, 1, 0, -theta);
    const double lift = kBeltThickness / 2 + kPart / 2 - kLayer;
    part = w.box(kPart, kPart, kPart, kMass, -std::sin(theta) * lift, 0, std::cos(theta) * lift);
    dMatrix3 r;
    dRFromAxisAndAngle(r, 0, 1, 0, -theta);
    dBodySetRotation(part, r);
    w.feeders->add(belt, MotionLaw::belt({std::cos(theta), 0, std::sin(theta)}, speed));
  }
  /// Part velocity along the incline's rising direction (m/s).
  double alongIncline() const {
    const Vec3 v = linearVelocity(part);
    return v.x * std::cos(theta) + v.z * std::sin(theta);
  }
  double theta;
  OdeWorld w;
  dGeomID belt;
  dBodyID part;
};

/// Steps until the part's x velocity is within kReached of `target`; returns the time (s) or
/// a negative value if not reached within `limit` s.
double timeToReach(OdeWorld& w, dBodyID part, double target, double limit, bool quick = false) {
  while (w.time < limit) {
    w.step(kStep, quick);
    if (std::fabs(dBodyGetLinearVel(part)[0] - target) < kReached) return w.time;
  }
  return -1.0;
}

}  // namespace

TEST(BeltContact, BoxReachesBeltSpeedAfterVOverMuG) {
  FlatBelt s(MotionLaw::belt({1, 0, 0}, kSpeed));
  const double expected = kSpeed / (kMu * kGravity);
  const double reached = timeToReach(s.w, s.part, kSpeed, 1.0);
  std::printf("[ measured ] belt: |v - V| < %g after %.4f s, V/(mu g) = %.5f s\n", kReached,
              reached, expected);
  EXPECT_NEAR(reached, expected, kTimeTolerance);
}

TEST(BeltContact, DroppedBoxGainsMuTimesItsImpactSpeedAtLanding) {
  // Dropped from 2 cm: the landing step's normal impulse m (v_impact + g h) stops the fall and
  // bounds the friction impulse by mu times it (Approx1 limits the rows by mu lambda_n in the
  // same LCP), so after landing the part needs (V - mu v_impact) / (mu g) more. Soft ERP = 0
  // keeps the landing penetration instead of pushing it out, which would add a normal impulse
  // that depends on how deep the part happened to be at the landing step.
  OdeWorld w;
  w.collider->setSurfaceCallback([](dGeomID, dGeomID, dContact* c, int n) {
    for (int i = 0; i < n; ++i) {
      c[i].surface = {};
      c[i].surface.mode = dContactApprox1 | dContactSoftERP;
      c[i].surface.mu = kMu;
      c[i].surface.soft_erp = 0.0;
    }
    return true;
  });
  dGeomID belt = w.staticBox(4.0, 1.0, kBeltThickness, 0, 0, -kBeltThickness / 2);
  dBodyID part = w.box(kPart, kPart, kPart, kMass, 0, 0, kPart / 2 + 0.02);
  w.feeders->add(belt, MotionLaw::belt({1, 0, 0}, kSpeed));
  double landed = -1.0, v_impact = 0.0, reached = -1.0;
  while (w.time < 0.5 && reached < 0) {
    const double vz = dBodyGetLinearVel(part)[2];
    const double t = w.time;
    w.step(kStep);
    if (landed < 0 && w.collider->contactCount() > 0) {
      landed = t;  // start of the landing step
      v_impact = -vz;
    }
    if (std::fabs(dBodyGetLinearVel(part)[0] - kSpeed) < kReached) reached = w.time;
  }
  ASSERT_GT(landed, 0.0);
  EXPECT_NEAR(v_impact, std::sqrt(2 * kGravity * 0.02), kGravity * kStep);  // free fall
  const double expected = (kSpeed - kMu * v_impact) / (kMu * kGravity);
  std::printf(
      "[ measured ] dropped box: V after %.4f s from landing, (V - mu v_imp)/(mu g) = "
      "%.5f s\n",
      reached - landed, expected);
  EXPECT_NEAR(reached - landed, expected, kTimeTolerance);
}

TEST(BeltContact, SlidingBoxAcceleratesAtMuG) {
  FlatBelt s(MotionLaw::belt({1, 0, 0}, kSpeed));
  // Half way to belt speed the part still slides: v = mu g t exactly (one LCP per step).
  const int steps = static_cast<int>(0.5 * kSpeed / (kMu * kGravity) / kStep);
  for (int i = 0; i < steps; ++i) s.w.step(kStep);
  EXPECT_NEAR(dBodyGetLinearVel(s.part)[0], kMu * kGravity * steps * kStep, kLcpTolerance);
}

TEST(BeltContact, MuIsACoefficientEvenIfTheApplicationLeftApprox1Out) {
  // The surface callback sets mode 0, where ODE reads mu as a force cap in newtons per row
  // (a 3 kg part would accelerate at 4 x 0.4 N / 3 kg = 0.53 m/s^2). The plugin forces
  // dContactApprox1 on feeder contacts: the part accelerates at mu g = 3.9 m/s^2.
  OdeWorld w;
  w.setSurface(0, kMu);
  dWorldSetContactSurfaceLayer(w.world, kLayer);
  dGeomID belt = w.staticBox(4.0, 1.0, kBeltThickness, 0, 0, -kBeltThickness / 2);
  dBodyID part = w.box(kPart, kPart, kPart, 3.0, 0, 0, kPart / 2 - kLayer);
  w.feeders->add(belt, MotionLaw::belt({1, 0, 0}, kSpeed));
  w.run(0.03, kStep);
  EXPECT_NEAR(dBodyGetLinearVel(part)[0], kMu * kGravity * 0.03, kLcpTolerance);
}

TEST(BeltContact, BoxSticksAtBeltSpeedOnceReached) {
  FlatBelt s(MotionLaw::belt({1, 0, 0}, kSpeed), -1.0);
  ASSERT_GT(timeToReach(s.w, s.part, kSpeed, 1.0), 0.0);
  double worst = 0.0;
  while (s.w.time < 1.5) {
    s.w.step(kStep);
    const Vec3 v = linearVelocity(s.part);
    const Vec3 omega = angularVelocity(s.part);
    worst = std::fmax(worst, std::fabs(v.x - kSpeed));
    worst = std::fmax(worst, std::fmax(std::fabs(v.y), std::fabs(v.z)));
    worst = std::fmax(worst, norm(omega));
  }
  EXPECT_LT(worst, kStickCreep);
  EXPECT_NEAR(dBodyGetPosition(s.part)[2], kPart / 2 - kLayer, kLcpTolerance);
}

TEST(BeltContact, NegativeSpeedCarriesThePartBackwards) {
  FlatBelt s(MotionLaw::belt({1, 0, 0}, -kSpeed));
  const double reached = timeToReach(s.w, s.part, -kSpeed, 1.0);
  EXPECT_NEAR(reached, kSpeed / (kMu * kGravity), kTimeTolerance);
  s.w.run(0.2, kStep);
  EXPECT_NEAR(dBodyGetLinearVel(s.part)[0], -kSpeed, kLcpTolerance);
  EXPECT_NEAR(dBodyGetLinearVel(s.part)[1], 0.0, kLcpTolerance);
}

TEST(BeltContact, QuickStepAlsoReachesBeltSpeedAfterVOverMuG) {
  FlatBelt s(MotionLaw::belt({1, 0, 0}, kSpeed));
  // Projected Gauss-Seidel with ODE's default 20 iterations does not converge the friction
  // of four corner contacts exactly: allow a few steps and a looser speed match.
  constexpr double kQuickTimeTolerance = 5 * kStep;
  constexpr double kQuickSpeedTolerance = 1e-3;  // m/s
  const double expected = kSpeed / (kMu * kGravity);
  double reached = -1.0;
  while (s.w.time < 1.0) {
    s.w.step(kStep, true);
    if (std::fabs(dBodyGetLinearVel(s.part)[0] - kSpeed) < kQuickSpeedTolerance) {
      reached = s.w.time;
      break;
    }
  }
  std::printf("[ measured ] belt, quickstep: |v - V| < %g after %.4f s, V/(mu g) = %.5f s\n",
              kQuickSpeedTolerance, reached, expected);
  EXPECT_NEAR(reached, expected, kQuickTimeTolerance);
  s.w.run(0.5, kStep, true);
  EXPECT_NEAR(dBodyGetLinearVel(s.part)[0], kSpeed, kQuickSpeedTolerance);
}

TEST(InclinedBelt, CarriesThePartUpAtBeltSpeedWhenTanThetaBelowMu) {
  const double theta = std::atan(0.75 * kMu);
  InclinedBelt s(theta, kSpeed);
  // Up the incline: friction mu g cos(theta) against gravity g sin(theta).
  const double a = kGravity * (kMu * std::cos(theta) - std::sin(theta));
  const double expected = kSpeed / a;
  double reached = -1.0;
  while (s.w.time < 2.0 && reached < 0) {
    s.w.step(kStep);
    if (std::fabs(s.alongIncline() - kSpeed) < kReached) reached = s.w.time;
  }
  std::printf("[ measured ] incline %.2f deg: V reached after %.4f s, V/a = %.5f s\n",
              theta * 180 / kPi, reached, expected);
  EXPECT_NEAR(reached, expected, kTimeTolerance);
  s.w.run(0.5, kStep);
  const Vec3 v = linearVelocity(s.part);
  EXPECT_NEAR(v.x, kSpeed * std::cos(theta), kLcpTolerance);
  EXPECT_NEAR(v.y, 0.0, kLcpTolerance);
  EXPECT_NEAR(v.z, kSpeed * std::sin(theta), kLcpTolerance);
}

TEST(InclinedBelt, PartSlidesDownWhenTanThetaAboveMu) {
  const double theta = std::atan(1.5 * kMu);
  InclinedBelt s(theta, kSpeed);
  // The belt moves up, the part down relative to it all the time: kinetic friction mu N up
  // the incline, net acceleration g (sin - mu cos) down the incline.
  const double a = kGravity * (std::sin(theta) - kMu * std::cos(theta));
  s.w.run(0.5, kStep);
  EXPECT_NEAR(s.alongIncline(), -a * s.w.time, kLcpTolerance);
  EXPECT_LT(s.alongIncline(), -0.5);
}

TEST(InclinedBelt, NegativeSpeedCarriesThePartDownAtBeltSpeed) {
  const double theta = std::atan(0.75 * kMu);
  InclinedBelt s(theta, -kSpeed);
  // Gravity and friction both act down the incline until the part moves at the belt's speed.
  const double a = kGravity * (kMu * std::cos(theta) + std::sin(theta));
  double reached = -1.0;
  while (s.w.time < 2.0 && reached < 0) {
    s.w.step(kStep);
    if (std::fabs(s.alongIncline() + kSpeed) < kReached) reached = s.w.time;
  }
  EXPECT_NEAR(reached, kSpeed / a, kTimeTolerance);
  s.w.run(0.5, kStep);
  const Vec3 v = linearVelocity(s.part);
  EXPECT_NEAR(v.x, -kSpeed * std::cos(theta), kLcpTolerance);
  EXPECT_NEAR(v.z, -kSpeed * std::sin(theta), kLcpTolerance);
}

// ---------------------------------------------------------------------------------------------
// A long part across two belts running in opposite directions

namespace {

constexpr double kRodLength = 0.3;  // m, along y, across both belts
constexpr double kRodWidth = 0.04;  // m, along x
constexpr double kBeltGap = 0.02;   // m between the belts' inner edges (at y = 0)

/// Angular velocity about z (rad/s) of a rod lying across two belts: y > 0 runs at
/// `v_left` (left when looking along +x), y < 0 at `v_right`, both along x.
struct TwoBelts {
  TwoBelts(double v_left, double v_right) {
    w.setSurface(dContactApprox1, 0.5);
    dWorldSetContactSurfaceLayer(w.world, kLayer);
    const double width = 0.5;
    dGeomID left = w.staticBox(2, width, 0.1, 0, kBeltGap / 2 + width / 2, -0.05);
    dGeomID right = w.staticBox(2, width, 0.1, 0, -kBeltGap / 2 - width / 2, -0.05);
    w.feeders->add(left, MotionLaw::belt({1, 0, 0}, v_left));
    w.feeders->add(right, MotionLaw::belt({1, 0, 0}, v_right));
    rod = w.box(kRodWidth, kRodLength, 0.02, 0.2, 0, 0, 0.01 - kLayer);
  }
  /// Largest |y| (m) of the rod's bottom corners relative to its centre, from its yaw.
  double outerCornerY() const {
    const dReal* q = dBodyGetQuaternion(rod);
    const double yaw = 2 * std::atan2(q[3], q[0]);
    return kRodWidth / 2 * std::fabs(std::sin(yaw)) + kRodLength / 2 * std::cos(yaw);
  }
  OdeWorld w;
  dBodyID rod;
};

}  // namespace

TEST(TwoBelts, PartSpanningOppositeBeltsTurnsAtSpeedDifferenceOverSpan) {
  // The rod's contacts are the corners of its footprint on each belt, the outermost at
  // |y| = y_max. Friction turns the rod clockwise (seen from above: +x on the left, -x on
  // the right) until the x speed of the outermost corners matches their belt: then they
  // stick along x (the Approx1 pyramid bounds each row on its own) while the inner corners
  // slide. So w_z = (v_right - v_left) / d with d = 2 y_max, the span of the outer contacts.
  constexpr double kV = 0.2;
  // rad/s: CFM = 1e-9 compliance of the sticking rows (~5e-10 rad/s measured) and round-off.
  constexpr double kOuterStickTolerance = 1e-8;
  for (double sign : {1.0, -1.0}) {
    SCOPED_TRACE(testing::Message() << "v_left = " << sign * kV);
    const double v_left = sign * kV, v_right = -sign * kV;
    TwoBelts s(v_left, v_right);
    s.w.run(0.06, kStep);  // spin-up: torque ~ mu m g L / 4 against I ~ m L^2 / 12: ~30 ms
    for (int k = 0; k < 100; ++k) {
      const double d = 2 * s.outerCornerY();  // contacts are made at the start of the step
      s.w.step(kStep);
      const double expected = (v_right - v_left) / d;
      ASSERT_NEAR(angularVelocity(s.rod).z, expected, kOuterStickTolerance) << "step " << k;
    }
    // Symmetric drive: the centre stays put.
    EXPECT_LT(std::hypot(position(s.rod).x, position(s.rod).y), 1e-6);
  }
}

// ---------------------------------------------------------------------------------------------
// Observation: records and slip

TEST(BeltObservation, SlipIsPartMinusBeltVelocityWhileSlidingAndZeroOnceStuck) {
  FeederSet::Options options;
  options.record_contacts = true;
  OdeWorld w(options);
  w.setSurface(dContactApprox1, kMu);
  dWorldSetContactSurfaceLayer(w.world, kLayer);
  dGeomID belt = w.staticBox(4.0, 1.0, kBeltThickness, 0, 0, -kBeltThickness / 2);
  dBodyID part = w.box(kPart, kPart, kPart, kMass, 0, 0, kPart / 2 - kLayer);
  w.feeders->add(belt, MotionLaw::belt({1, 0, 0}, kSpeed));

  w.run(0.03, kStep);                          // sliding: reaches V only after 0.076 s
  ASSERT_EQ(w.feeders->records().size(), 4u);  // a box face on a face: four corners
  const double v = dBodyGetLinearVel(part)[0];
  ASSERT_LT(v, kSpeed - 0.05);
  for (const ContactRecord& r : w.feeders->records()) {
    EXPECT_EQ(r.feeder, belt);
    EXPECT_EQ(r.part, dBodyGetFirstGeom(part));
    const Vec3 slip = w.feeders->slip(r);
    EXPECT_NEAR(slip.x, v - kSpeed, kStickCreep);
    EXPECT_NEAR(slip.y, 0.0, kStickCreep);
    EXPECT_NEAR(slip.z, 0.0, kStickCreep);
  }

  w.run(0.3, kStep);  // stuck
  ASSERT_EQ(w.feeders->records().size(), 4u);
  for (const ContactRecord& r : w.feeders->records()) {
    EXPECT_LT(norm(w.feeders->slip(r)), kStickCreep);
  }
}

TEST(BeltObservation, ContactsDrivenPerFeederEqualsItsContactsInTheStep) {
  // The rod across two belts touches each; count each belt's contacts with dCollide (same
  // positions, same contact limit as the collider) before every step and compare.
  TwoBelts s(0.2, -0.2);
  dGeomID rod = dBodyGetFirstGeom(s.rod);
  dGeomID belts[2] = {nullptr, nullptr};
  int found = 0;
  for (int i = 0; i < dSpaceGetNumGeoms(s.w.space); ++i) {
    dGeomID g = dSpaceGetGeom(s.w.space, i);
    if (s.w.feeders->contains(g)) belts[found++] = g;
  }
  ASSERT_EQ(found, 2);
  for (int k = 0; k < 50; ++k) {
    int expected[2];
    for (int b = 0; b < 2; ++b) {
      dContactGeom c[8];
      expected[b] = dCollide(belts[b], rod, 8, c, sizeof(dContactGeom));
    }
    s.w.step(kStep);
    for (int b = 0; b < 2; ++b) {
      ASSERT_GT(expected[b], 0);
      ASSERT_EQ(s.w.feeders->stats(belts[b]).contacts_driven, expected[b]) << "step " << k;
      ASSERT_EQ(s.w.feeders->stats(belts[b]).contacts_undriven, 0);
    }
  }
}

}  // namespace rheofeed::test
