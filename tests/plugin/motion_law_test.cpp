// SPDX-License-Identifier: MIT
// Motion laws on their own (no ODE): the surface velocity they give at a point, frames, time
// profiles, and what a frozen step law reports. Expected values are written out by hand.
#include "rheofeed/motion_law.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace rheofeed {
namespace {

// The laws compute with a few double operations per component.
constexpr double kRoundOff = 1e-15;

void expectVec(const Vec3& actual, double x, double y, double z, double tolerance = kRoundOff) {
  EXPECT_NEAR(actual.x, x, tolerance);
  EXPECT_NEAR(actual.y, y, tolerance);
  EXPECT_NEAR(actual.z, z, tolerance);
}

const Vec3 kUp{0, 0, 1};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Twist laws

TEST(TwistLaw, TurntableFollowsTheRightHandRule) {
  // w = 2 about +z through the origin: at (r cos a, r sin a) the surface moves at w r along
  // (-sin a, cos a): counter-clockwise seen from above.
  const StepLaw law = MotionLaw::rotation({0, 0, 2.0}, {0, 0, 0}).evaluate(0, nullptr);
  for (double a : {0.0, 0.7, 2.0, -2.5}) {
    SCOPED_TRACE(a);
    const double r = 0.5;
    const Vec3 c = law.tangentialVelocity({r * std::cos(a), r * std::sin(a), 0}, kUp);
    expectVec(c, -2.0 * r * std::sin(a), 2.0 * r * std::cos(a), 0.0);
  }
}

TEST(TwistLaw, PapersFormIsTheNegatedAngularVelocity) {
  // Fusai & Tasora print v + r x w; with w' = -w our v + w' x r equals it.
  const Vec3 v{0.1, -0.2, 0.05}, w{0.3, 0.4, -1.1}, o{0.2, 0.1, 0.0}, p{1.0, -0.5, 0.0};
  const Vec3 r{p.x - o.x, p.y - o.y, p.z - o.z};
  const Vec3 paper{v.x + r.y * w.z - r.z * w.y, v.y + r.z * w.x - r.x * w.z,
                   v.z + r.x * w.y - r.y * w.x};
  const StepLaw law = MotionLaw::twist({v, {-w.x, -w.y, -w.z}, o}).evaluate(0, nullptr);
  const Vec3 c = law.tangentialVelocity(p, kUp);
  expectVec(c, paper.x, paper.y, 0.0);  // normal part (z) dropped
}

TEST(TwistLaw, NormalComponentIsDiscarded) {
  const double s = 1.0 / std::sqrt(3.0);
  const Vec3 n{s, s, s};
  const StepLaw law = MotionLaw::translation({1, 2, 3}).evaluate(0, nullptr);
  // v - (v . n) n with v . n = 6 / sqrt(3): (1, 2, 3) - (2, 2, 2).
  expectVec(law.tangentialVelocity({5, 6, 7}, n), -1.0, 0.0, 1.0, 4 * kRoundOff);
}

TEST(TwistLaw, ZeroTwistIsTheStillSurface) {
  EXPECT_TRUE(MotionLaw().evaluate(0, nullptr).isZero());
  EXPECT_TRUE(MotionLaw::rotation({0, 0, 0}, {1, 2, 3}).evaluate(0, nullptr).isZero());
  EXPECT_FALSE(MotionLaw::rotation({0, 0, 1}, {}).evaluate(0, nullptr).isZero());
}

// ---------------------------------------------------------------------------------------------
// Belts

TEST(BeltLaw, RunsAtFullSpeedAlongAnyFaceItIsNotNormalTo) {
  // Direction x; a face inclined by 30 degrees about y (normal (-sin, 0, cos)): the belt runs
  // at |V| along (cos, 0, sin), not at V cos.
  const double a = 30.0 * 3.14159265358979323846 / 180.0;
  const StepLaw law = MotionLaw::belt({1, 0, 0}, 0.3).evaluate(0, nullptr);
  expectVec(law.tangentialVelocity({0, 0, 0}, {-std::sin(a), 0, std::cos(a)}), 0.3 * std::cos(a),
            0.0, 0.3 * std::sin(a));
}

TEST(BeltLaw, NegativeSpeedReverses) {
  const StepLaw law = MotionLaw::belt({0, 2, 0}, -0.25).evaluate(0, nullptr);
  expectVec(law.tangentialVelocity({3, 4, 0}, kUp), 0.0, -0.25, 0.0);
}

TEST(BeltLaw, EndFaceNormalToTheDirectionDoesNotMove) {
  const StepLaw law = MotionLaw::belt({1, 0, 0}, 0.3).evaluate(0, nullptr);
  expectVec(law.tangentialVelocity({2, 0, 0}, {1, 0, 0}), 0, 0, 0, 0.0);
  expectVec(law.tangentialVelocity({-2, 0, 0}, {-1, 0, 0}), 0, 0, 0, 0.0);
}

TEST(BeltLaw, DirectionOfAnyPositiveLengthGivesTheSameBelt) {
  // "any length > 0": the direction is only a direction, however it is scaled.
  for (double length : {1e-300, 1e-160, 1e-3, 1.0, 7.0, 1e160, 1e300}) {
    SCOPED_TRACE(length);
    const StepLaw law = MotionLaw::belt({length, length, 0}, 0.3).evaluate(0, nullptr);
    const double h = 0.3 / std::sqrt(2.0);
    expectVec(law.tangentialVelocity({0, 0, 0}, kUp), h, h, 0.0);
  }
}

// ---------------------------------------------------------------------------------------------
// Frames

namespace {

/// Pose turned by 90 degrees about z and moved to (1, 2, 3).
Pose turnedPose() {
  Pose pose;
  pose.position = {1, 2, 3};
  const double r[9] = {0, -1, 0, 1, 0, 0, 0, 0, 1};  // body x -> world y, body y -> world -x
  for (int i = 0; i < 9; ++i) pose.rotation[i] = r[i];
  return pose;
}

}  // namespace

TEST(BodyFrame, BeltDirectionTurnsWithTheBody) {
  const Pose pose = turnedPose();
  const StepLaw law = MotionLaw::belt({1, 0, 0}, 0.3, Frame::Body).evaluate(0, &pose);
  expectVec(law.tangentialVelocity({0, 0, 0}, kUp), 0.0, 0.3, 0.0);
}

TEST(BodyFrame, TwistOriginMovesAndAxesTurnWithTheBody) {
  // Body-frame twist: v = (0.1, 0, 0), w = (2, 0, 0)... turned, w becomes world (0, 2, 0), v
  // world (0, 0.1, 0), and the origin (0.5, 0, 0) is at world (1, 2.5, 3).
  const Pose pose = turnedPose();
  const MotionLaw law = MotionLaw::twist({{0.1, 0, 0}, {2, 0, 0}, {0.5, 0, 0}}, Frame::Body);
  const StepLaw frozen = law.evaluate(0, &pose);
  // At p = (1.5, 2.5, 3): p - O = (0.5, 0, 0); w x (p - O) = (0, 0, -1); plus v = (0, 0.1, 0).
  // Tangential to the normal (0, 0, 1): (0, 0.1, 0).
  expectVec(frozen.tangentialVelocity({1.5, 2.5, 3}, kUp), 0.0, 0.1, 0.0);
  // With a normal along x the z part survives: (0, 0.1, -1).
  expectVec(frozen.tangentialVelocity({1.5, 2.5, 3}, {1, 0, 0}), 0.0, 0.1, -1.0);
}

TEST(BodyFrame, WithoutAPoseTheLawStaysInTheWorldFrame) {
  const StepLaw law = MotionLaw::belt({1, 0, 0}, 0.3, Frame::Body).evaluate(0, nullptr);
  expectVec(law.tangentialVelocity({0, 0, 0}, kUp), 0.3, 0.0, 0.0);
}

// ---------------------------------------------------------------------------------------------
// Time profiles

TEST(TimeProfileValues, RampIsLinearBetweenItsEndsAndHeldOutside) {
  const TimeProfile ramp = TimeProfile::ramp(1.0, 3.0, 0.5, 2.5);
  EXPECT_EQ(ramp(-10.0), 0.5);
  EXPECT_EQ(ramp(1.0), 0.5);
  EXPECT_DOUBLE_EQ(ramp(1.5), 1.0);
  EXPECT_DOUBLE_EQ(ramp(2.0), 1.5);
  EXPECT_DOUBLE_EQ(ramp(2.75), 2.25);
  EXPECT_EQ(ramp(3.0), 2.5);
  EXPECT_EQ(ramp(1e9), 2.5);
  EXPECT_FALSE(ramp.isConstant());
}

TEST(TimeProfileValues, OnOffIsOneOnAHalfOpenInterval) {
  const TimeProfile on_off = TimeProfile::onOff(1.0, 2.0);
  EXPECT_EQ(on_off(0.999), 0.0);
  EXPECT_EQ(on_off(1.0), 1.0);
  EXPECT_EQ(on_off(1.999), 1.0);
  EXPECT_EQ(on_off(2.0), 0.0);
  const TimeProfile forever = TimeProfile::onOff(1.0);
  EXPECT_EQ(forever(1e300), 1.0);
  EXPECT_EQ(forever(0.5), 0.0);
}

TEST(TimeProfileValues, ConstantAndFunction) {
  EXPECT_EQ(TimeProfile()(123.0), 1.0);
  EXPECT_TRUE(TimeProfile().isConstant());
  EXPECT_EQ(TimeProfile::constant(0.25)(5.0), 0.25);
  const TimeProfile f = TimeProfile::function([](double t) { return 2 * t; });
  EXPECT_EQ(f(1.5), 3.0);
  EXPECT_FALSE(f.isConstant());
}

TEST(TimeProfileValues, ProfileScalesEveryVelocityOfTheLaw) {
  const MotionLaw base = MotionLaw::twist({{0.2, 0, 0}, {0, 0, 1}, {0, 0, 0}});
  const MotionLaw half = base.withProfile(TimeProfile::ramp(0.0, 2.0, 0.0, 1.0));
  // At t = 1 the scale is 0.5: v = 0.1 and w = 0.5, so at (0, 1, 0): (0.1 - 0.5, 0, 0).
  expectVec(half.evaluate(1.0, nullptr).tangentialVelocity({0, 1, 0}, kUp), -0.4, 0.0, 0.0);
  const MotionLaw belt = MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::constant(-2.0));
  expectVec(belt.evaluate(0, nullptr).tangentialVelocity({0, 0, 0}, kUp), -0.6, 0.0, 0.0);
}

TEST(TimeProfileValues, TimeVaryingOnlyWhenSomethingDependsOnTime) {
  EXPECT_FALSE(MotionLaw::belt({1, 0, 0}, 0.3).isTimeVarying());
  EXPECT_FALSE(
      MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::constant(2)).isTimeVarying());
  EXPECT_TRUE(MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::onOff(1)).isTimeVarying());
  EXPECT_TRUE(MotionLaw::twistFunction([](double) { return Twist{}; }).isTimeVarying());
  const SurfaceField field = [](const Vec3&, const Vec3&, double) { return Vec3{}; };
  EXPECT_FALSE(MotionLaw::field(field).isTimeVarying());
  EXPECT_TRUE(MotionLaw::field(field, true).isTimeVarying());
}

// ---------------------------------------------------------------------------------------------
// Frozen laws

TEST(StepLawState, NonFiniteProfileOrTwistFunctionIsReportedWithItsValue) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const StepLaw bad_profile = MotionLaw::belt({1, 0, 0}, 0.3)
                                  .withProfile(TimeProfile::function([nan](double) { return nan; }))
                                  .evaluate(0.5, nullptr);
  EXPECT_FALSE(bad_profile.finite());
  EXPECT_NE(bad_profile.problem().find("profile"), std::string::npos) << bad_profile.problem();
  EXPECT_NE(bad_profile.problem().find("nan"), std::string::npos) << bad_profile.problem();

  const StepLaw bad_twist = MotionLaw::twistFunction([](double) {
                              return Twist{{}, {}, {0, std::numeric_limits<double>::infinity(), 0}};
                            }).evaluate(0.5, nullptr);
  EXPECT_FALSE(bad_twist.finite());
  EXPECT_NE(bad_twist.problem().find("twist.origin"), std::string::npos) << bad_twist.problem();
  EXPECT_NE(bad_twist.problem().find("inf"), std::string::npos) << bad_twist.problem();

  const StepLaw good = MotionLaw::belt({1, 0, 0}, 0.3).evaluate(0.5, nullptr);
  EXPECT_TRUE(good.finite());
  EXPECT_TRUE(good.problem().empty());
}

TEST(StepLawState, TwistFunctionIsCalledOncePerEvaluation) {
  int calls = 0;
  const MotionLaw law = MotionLaw::twistFunction([&calls](double t) {
    ++calls;
    return Twist{{t, 0, 0}, {}, {}};
  });
  const StepLaw frozen = law.evaluate(0.25, nullptr);
  EXPECT_EQ(calls, 1);
  for (int i = 0; i < 10; ++i) frozen.tangentialVelocity({0.1 * i, 0, 0}, kUp);
  EXPECT_EQ(calls, 1);
  expectVec(frozen.tangentialVelocity({0, 0, 0}, kUp), 0.25, 0.0, 0.0);
}

TEST(StepLawState, SameMotionComparesWhatTheSurfaceDoes) {
  const MotionLaw belt = MotionLaw::belt({1, 0, 0}, 0.3);
  EXPECT_TRUE(belt.evaluate(0, nullptr).sameMotionAs(belt.evaluate(7, nullptr)));
  EXPECT_FALSE(
      belt.evaluate(0, nullptr).sameMotionAs(MotionLaw::belt({1, 0, 0}, 0.2).evaluate(0, nullptr)));
  const MotionLaw ramp = belt.withProfile(TimeProfile::ramp(0, 1, 0, 1));
  EXPECT_FALSE(ramp.evaluate(0.2, nullptr).sameMotionAs(ramp.evaluate(0.4, nullptr)));
  EXPECT_TRUE(ramp.evaluate(2, nullptr).sameMotionAs(ramp.evaluate(3, nullptr)));
  // Two still surfaces are the same whatever law they come from.
  EXPECT_TRUE(MotionLaw()
                  .evaluate(0, nullptr)
                  .sameMotionAs(belt.withProfile(TimeProfile::onOff(5)).evaluate(0, nullptr)));
}

}  // namespace rheofeed
