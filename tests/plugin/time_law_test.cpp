// SPDX-License-Identifier: MIT
// Laws that change: time profiles (ramp, on/off), twist functions and direct fields of time,
// laws in a body frame that follow a moved or turned kinematic body, and sleeping parts that
// must wake when (and only when) the surface under them starts to move.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

#include "ode_world.hpp"

namespace rheofeed::test {
namespace {

constexpr double kStep = 0.001;  // s
constexpr double kMu = 0.4;
constexpr double kSpeed = 0.3;   // m/s
constexpr double kPart = 0.1;    // m, cubic part of 1 kg
constexpr double kLayer = 1e-4;  // m, contact surface layer; parts start at this depth
// A sticking part follows its surface exactly but for the CFM = 1e-9 compliance of the rows
// (about 2e-8 m/s when the friction load changes; see belt_contact_test.cpp).
constexpr double kFollowTolerance = 5e-8;  // m/s
// Semi-implicit Euler stops the spin-up exactly in the step containing the analytic time.
constexpr double kTimeTolerance = kStep;

/// A flat static table (top at z = 0) and a cubic part resting on it at the origin. The table
/// is registered as a feeder with `law` unless `law` is null.
struct Table {
  explicit Table(const MotionLaw* law, bool kinematic_carrier = false) {
    w.setSurface(dContactApprox1, kMu);
    dWorldSetContactSurfaceLayer(w.world, kLayer);
    table = dCreateBox(w.space, 2.0, 2.0, 0.1);
    if (kinematic_carrier) {
      carrier = dBodyCreate(w.world);
      dBodySetKinematic(carrier);
      dGeomSetBody(table, carrier);
      dBodySetPosition(carrier, 0, 0, -0.05);
    } else {
      dGeomSetPosition(table, 0, 0, -0.05);
    }
    part = w.box(kPart, kPart, kPart, 1.0, 0, 0, kPart / 2 - kLayer);
    if (law) w.feeders->add(table, *law);
  }
  OdeWorld w;
  dGeomID table;
  dBodyID carrier = nullptr;
  dBodyID part;
};

double vx(dBodyID b) {
  return dBodyGetLinearVel(b)[0];
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Time profiles

TEST(TimeProfileOnBelt, RampChangesTheBeltSpeedLinearlyAndThePartFollows) {
  // s(t) = 0 before 0.1 s, 1 after 0.5 s: the belt accelerates at V / 0.4 s = 0.75 m/s^2,
  // below mu g = 3.9 m/s^2, so the part sticks and moves at V s(t) of the step's start time.
  const MotionLaw law =
      MotionLaw::belt({1, 0, 0}, kSpeed).withProfile(TimeProfile::ramp(0.1, 0.5, 0.0, 1.0));
  Table s(&law);
  double worst = 0.0;
  while (s.w.time < 0.7 - kStep / 2) {
    const double t = s.w.time;
    s.w.step(kStep);
    const double scale = t <= 0.1 ? 0.0 : t >= 0.5 ? 1.0 : (t - 0.1) / 0.4;
    worst = std::fmax(worst, std::fabs(vx(s.part) - kSpeed * scale));
  }
  EXPECT_LT(worst, kFollowTolerance);
  EXPECT_NEAR(vx(s.part), kSpeed, kFollowTolerance);
}

TEST(TimeProfileOnBelt, OnOffStartsAndStopsTheBelt) {
  constexpr double kOn = 0.2, kOff = 0.6;
  const MotionLaw law =
      MotionLaw::belt({1, 0, 0}, kSpeed).withProfile(TimeProfile::onOff(kOn, kOff));
  Table s(&law);
  const double spin_up = kSpeed / (kMu * kGravity);  // also the stopping time
  double started = -1, reached = -1, stopped = -1;
  while (s.w.time < kOff + 2 * spin_up) {
    s.w.step(kStep);
    const double v = vx(s.part);
    if (started < 0 && v > 1e-6) started = s.w.time;
    if (reached < 0 && std::fabs(v - kSpeed) < 1e-6) reached = s.w.time;
    if (reached > 0 && stopped < 0 && s.w.time > kOff && std::fabs(v) < 1e-6) stopped = s.w.time;
  }
  // Off until kOn: the first step that starts at t >= kOn moves the part.
  EXPECT_NEAR(started, kOn + kStep, kStep / 2);
  EXPECT_NEAR(reached, kOn + spin_up, kTimeTolerance);
  // Off at kOff: the part slides to a stop, decelerating at mu g.
  EXPECT_NEAR(stopped, kOff + spin_up, kTimeTolerance);
  EXPECT_NEAR(vx(s.part), 0.0, kFollowTolerance);
}

// ---------------------------------------------------------------------------------------------
// Twist functions and fields of time

TEST(TwistFunction, PartFollowsATwistThatChangesWithTime) {
  constexpr double kAcceleration = 1.0;  // m/s^2 < mu g: the part sticks
  const MotionLaw law = MotionLaw::twistFunction([](double t) {
    return Twist{{kAcceleration * t, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  });
  Table s(&law);
  double worst = 0.0;
  for (int i = 0; i < 300; ++i) {
    const double t = s.w.time;
    s.w.step(kStep);
    worst = std::fmax(worst, std::fabs(vx(s.part) - kAcceleration * t));
  }
  EXPECT_LT(worst, kFollowTolerance);
}

TEST(SurfaceFieldLaw, PartFollowsAFieldThatTurnsWithTime) {
  // c(t) = V (cos W t, sin W t, 0): its rate V W = 1.26 m/s^2 < mu g, the part sticks.
  constexpr double kV = 0.2, kW = 2 * kPi;
  const MotionLaw law = MotionLaw::field(
      [](const Vec3&, const Vec3&, double t) {
        return Vec3{kV * std::cos(kW * t), kV * std::sin(kW * t), 0.5 /* normal: dropped */};
      },
      true);
  Table s(&law);
  s.w.run(0.1, kStep);  // spin-up from rest to V: V / (mu g) = 0.05 s
  double worst = 0.0;
  for (int i = 0; i < 500; ++i) {
    const double t = s.w.time;
    s.w.step(kStep);
    const Vec3 v = linearVelocity(s.part);
    worst = std::fmax(worst, std::fabs(v.x - kV * std::cos(kW * t)));
    worst = std::fmax(worst, std::fabs(v.y - kV * std::sin(kW * t)));
    worst = std::fmax(worst, std::fabs(v.z));
  }
  EXPECT_LT(worst, kFollowTolerance);
}

TEST(SurfaceFieldLaw, FieldEqualToARotationMovesThePartLikeTheRotationLaw) {
  constexpr double kW = 1.5;  // rad/s about z through (0.2, 0, 0)
  const MotionLaw rotation = MotionLaw::rotation({0, 0, kW}, {0.2, 0, 0});
  const MotionLaw field = MotionLaw::field([](const Vec3& p, const Vec3&, double) {
    return Vec3{-kW * p.y, kW * (p.x - 0.2), 0.0};  // w x (p - O), written out
  });
  Table a(&rotation), b(&field);
  a.w.run(0.3, kStep);
  b.w.run(0.3, kStep);
  ASSERT_GT(norm(linearVelocity(a.part)), 0.2);
  // The two laws compute c_t with different operation orders: round-off only.
  EXPECT_LT(maxDifference(stateOf(a.part), stateOf(b.part)), 1e-12);
}

// ---------------------------------------------------------------------------------------------
// Laws in the body frame of a kinematic carrier

TEST(BodyFrameLaw, BeltDirectionTurnsWithItsKinematicCarrier) {
  const MotionLaw law = MotionLaw::belt({1, 0, 0}, kSpeed, Frame::Body);
  Table s(&law, true);
  const double spin_up = kSpeed / (kMu * kGravity);
  // Carrier turned by 90 degrees about z (teleported at rest): body x is world +y.
  dMatrix3 r;
  dRFromAxisAndAngle(r, 0, 0, 1, kPi / 2);
  dBodySetRotation(s.carrier, r);
  s.w.run(spin_up + 0.05, kStep);
  EXPECT_NEAR(linearVelocity(s.part).x, 0.0, kFollowTolerance);
  EXPECT_NEAR(linearVelocity(s.part).y, kSpeed, kFollowTolerance);
  // Turned on to 180 degrees: body x is world -x. Reversing takes twice the spin-up.
  dRFromAxisAndAngle(r, 0, 0, 1, kPi);
  dBodySetRotation(s.carrier, r);
  s.w.run(2 * spin_up + 0.05, kStep);
  EXPECT_NEAR(linearVelocity(s.part).x, -kSpeed, kFollowTolerance);
  EXPECT_NEAR(linearVelocity(s.part).y, 0.0, kFollowTolerance);
}

TEST(BodyFrameLaw, PartOnAMovingTurnedCarrierGetsCarrierPlusSurfaceVelocity) {
  const MotionLaw law = MotionLaw::belt({1, 0, 0}, kSpeed, Frame::Body);
  Table s(&law, true);
  const double yaw = kPi / 6;
  dMatrix3 r;
  dRFromAxisAndAngle(r, 0, 0, 1, yaw);
  dBodySetRotation(s.carrier, r);
  const Vec3 u{0.0, 0.1, 0.0};  // the carrier translates (kinematic: ODE moves it)
  dBodySetLinearVel(s.carrier, u.x, u.y, u.z);
  s.w.run(0.3, kStep);
  const Vec3 v = linearVelocity(s.part);
  EXPECT_NEAR(v.x, u.x + kSpeed * std::cos(yaw), kFollowTolerance);
  EXPECT_NEAR(v.y, u.y + kSpeed * std::sin(yaw), kFollowTolerance);
  EXPECT_NEAR(v.z, 0.0, kFollowTolerance);
}

TEST(BodyFrameLaw, TwistFunctionRotatesAboutTheMovedAndFlippedCarrierOrigin) {
  // w = +2 about the body's origin, given in the body frame by a twist function. The carrier
  // is moved to (0.5, 0.3) and flipped upside down (180 degrees about x; the box is
  // symmetric): body z is world -z, so the surface turns clockwise about the carrier's origin.
  constexpr double kW = 2.0;
  const MotionLaw law = MotionLaw::twistFunction(
      [](double) {
        return Twist{{0, 0, 0}, {0, 0, kW}, {0, 0, 0}};
      },
      Frame::Body);
  OdeWorld w;
  w.setSurface(dContactApprox1, kMu);
  dWorldSetContactSurfaceLayer(w.world, kLayer);
  dGeomID table = dCreateBox(w.space, 2.0, 2.0, 0.1);
  dBodyID carrier = dBodyCreate(w.world);
  dBodySetKinematic(carrier);
  dGeomSetBody(table, carrier);
  dBodySetPosition(carrier, 0.5, 0.3, -0.05);
  dMatrix3 r;
  dRFromAxisAndAngle(r, 1, 0, 0, kPi);
  dBodySetRotation(carrier, r);
  w.feeders->add(table, law);
  const double small = 0.05;  // m, a small part so the field varies little across it
  dBodyID part = w.box(small, small, small, 0.1, 0.5 + 0.1, 0.3, small / 2 - kLayer);
  w.run(0.2, kStep);  // spin-up: w r / (mu g) = 0.05 s
  const Vec3 before = position(part);
  w.step(kStep);
  // v = (-w) z x (p - O) with p - O = (dx, dy, 0): (w dy, -w dx, 0).
  const Vec3 v = linearVelocity(part);
  EXPECT_NEAR(v.x, kW * (before.y - 0.3), kFollowTolerance);
  EXPECT_NEAR(v.y, -kW * (before.x - 0.5), kFollowTolerance);
  EXPECT_LT(v.y, -0.1);  // clockwise: at +x of the centre the surface moves towards -y
  EXPECT_NEAR(angularVelocity(part).z, -kW, kFollowTolerance);
}

// ---------------------------------------------------------------------------------------------
// Sleeping parts

namespace {

/// A part that ODE has auto-disabled on a feeder whose surface is still.
struct SleepingPart {
  explicit SleepingPart(const MotionLaw& law) : s(&law) {
    // ODE's defaults: asleep after 10 steps with |v| < 0.01 m/s and |w| < 0.01 rad/s. A body
    // copies the world's settings when created, so the part takes them over explicitly.
    dWorldSetAutoDisableFlag(s.w.world, 1);
    dBodySetAutoDisableDefaults(s.part);
    for (int i = 0; i < 200 && dBodyIsEnabled(s.part); ++i) s.w.step(kStep);
  }
  Table s;
};

}  // namespace

TEST(SleepingPart, StaysAsleepWhileNothingChanges) {
  // A still belt, then a belt whose on/off profile is still off: the frozen surface motion
  // stays zero, so the part is not woken (a body woken every step would never sleep).
  for (const MotionLaw& law :
       {MotionLaw::belt({1, 0, 0}, 0.0),
        MotionLaw::belt({1, 0, 0}, kSpeed).withProfile(TimeProfile::onOff(10.0))}) {
    SleepingPart sp(law);
    ASSERT_FALSE(dBodyIsEnabled(sp.s.part)) << "ODE did not put the resting part to sleep";
    const BodyState asleep = stateOf(sp.s.part);
    for (int i = 0; i < 500; ++i) {
      sp.s.w.step(kStep);
      ASSERT_FALSE(dBodyIsEnabled(sp.s.part)) << "woken at step " << i;
    }
    EXPECT_EQ(sp.s.w.feeders->stats(sp.s.table).bodies_woken, 0u);
    const BodyState after = stateOf(sp.s.part);
    EXPECT_EQ(std::memcmp(&asleep, &after, sizeof asleep), 0);
  }
}

TEST(SleepingPart, IsWokenAndCarriedWhenTheBeltIsSwitchedOnWithSetLaw) {
  SleepingPart sp(MotionLaw::belt({1, 0, 0}, 0.0));
  ASSERT_FALSE(dBodyIsEnabled(sp.s.part));
  sp.s.w.feeders->setLaw(sp.s.table, MotionLaw::belt({1, 0, 0}, kSpeed));
  sp.s.w.step(kStep);
  EXPECT_TRUE(dBodyIsEnabled(sp.s.part));
  EXPECT_EQ(sp.s.w.feeders->stats(sp.s.table).bodies_woken, 1u);
  EXPECT_NEAR(vx(sp.s.part), kMu * kGravity * kStep, 1e-9);  // first step of the spin-up
  sp.s.w.run(kSpeed / (kMu * kGravity) + 0.05, kStep);
  EXPECT_NEAR(vx(sp.s.part), kSpeed, kFollowTolerance);
  EXPECT_TRUE(dBodyIsEnabled(sp.s.part));
}

TEST(SleepingPart, IsWokenAndCarriedWhenAProfileSwitchesTheBeltOn) {
  SleepingPart sp(MotionLaw::belt({1, 0, 0}, kSpeed).withProfile(TimeProfile::onOff(0.5)));
  ASSERT_FALSE(dBodyIsEnabled(sp.s.part));
  ASSERT_LT(sp.s.w.time, 0.5);
  while (sp.s.w.time < 0.5 - kStep / 2) {
    sp.s.w.step(kStep);
    ASSERT_FALSE(dBodyIsEnabled(sp.s.part)) << "woken early at t = " << sp.s.w.time;
  }
  sp.s.w.step(kStep);  // the first step starting at t >= 0.5
  EXPECT_TRUE(dBodyIsEnabled(sp.s.part));
  EXPECT_EQ(sp.s.w.feeders->stats(sp.s.table).bodies_woken, 1u);
  sp.s.w.run(kSpeed / (kMu * kGravity) + 0.05, kStep);
  EXPECT_NEAR(vx(sp.s.part), kSpeed, kFollowTolerance);
}

TEST(SleepingPart, OnlyPartsOnTheChangedFeederAreWoken) {
  SleepingPart sp(MotionLaw::belt({1, 0, 0}, 0.0));
  // A second, plain table with its own sleeping part, far away.
  dGeomID other_table = sp.s.w.staticBox(1.0, 1.0, 0.1, 5.0, 0, -0.05);
  (void)other_table;
  dBodyID other = sp.s.w.box(kPart, kPart, kPart, 1.0, 5.0, 0, kPart / 2 - kLayer);
  for (int i = 0; i < 200 && dBodyIsEnabled(other); ++i) sp.s.w.step(kStep);
  ASSERT_FALSE(dBodyIsEnabled(other));
  ASSERT_FALSE(dBodyIsEnabled(sp.s.part));
  sp.s.w.feeders->setLaw(sp.s.table, MotionLaw::belt({1, 0, 0}, kSpeed));
  sp.s.w.run(0.05, kStep);
  EXPECT_TRUE(dBodyIsEnabled(sp.s.part));
  EXPECT_FALSE(dBodyIsEnabled(other));
}

}  // namespace rheofeed::test
