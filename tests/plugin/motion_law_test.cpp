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

// Profiles multiply (the documented "multiplied by profile(t)"): a second profile used to
// replace the first, so a ramp followed by an on/off window lost the ramp (the C API's
// rfFeederSetSetRamp then rfFeederSetSetOnOff did).
TEST(TimeProfileValues, ProfilesOfALawMultiply) {
  const MotionLaw belt = MotionLaw::belt({1, 0, 0}, 0.3);
  const MotionLaw six =
      belt.withProfile(TimeProfile::constant(2)).withProfile(TimeProfile::constant(3));
  expectVec(six.evaluate(0, nullptr).tangentialVelocity({0, 0, 0}, kUp), 1.8, 0.0, 0.0);
  EXPECT_FALSE(six.isTimeVarying());
  // A ramp 0 -> 1 over [0, 2] s, then on for t < 3 s: 0.3 x 0.5 at 1 s, 0.3 at 2.5 s, 0 at 3 s.
  const MotionLaw started =
      belt.withProfile(TimeProfile::ramp(0, 2, 0, 1)).withProfile(TimeProfile::onOff(0, 3));
  expectVec(started.evaluate(1, nullptr).tangentialVelocity({0, 0, 0}, kUp), 0.15, 0.0, 0.0);
  expectVec(started.evaluate(2.5, nullptr).tangentialVelocity({0, 0, 0}, kUp), 0.3, 0.0, 0.0);
  expectVec(started.evaluate(3, nullptr).tangentialVelocity({0, 0, 0}, kUp), 0.0, 0.0, 0.0);
  EXPECT_TRUE(started.isTimeVarying());
  // Each factor is validated.
  EXPECT_THROW(belt.withProfile(TimeProfile::onOff(0, 3))
                   .withProfile(TimeProfile::ramp(2, 1, 0, 1))
                   .validate("test"),
               std::invalid_argument);
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

// ---------------------------------------------------------------------------------------------
// Secant of a rotating law over a step (motion_law.hpp, "Pass the step length")
//
// Oracle: the rigid motion of the frozen twist over h, written out here. A twist (v, w, O) is
// the screw v_par + w x (p - O') with v_par = (v . w) w / |w|^2 and O' = O + (w x v) / |w|^2
// (check: v_par + w x (O - O') = v_par - w x (w x v) / |w|^2 = v_par + v_perp = v). Its flow
// maps p to O' + Rot(w h)(p - O') + h v_par, with Rot from Rodrigues' vector formula. A point
// moved by h c must land there.

namespace {

// Points and displacements of order 1 m built from a few tens of roundings.
constexpr double kLandingTolerance = 1e-14;  // m

/// x rotated by `angle` (rad, right hand) about the unit axis k (Rodrigues).
Vec3 rotated(const Vec3& k, double angle, const Vec3& x) {
  return std::cos(angle) * x + std::sin(angle) * cross(k, x) +
         ((1 - std::cos(angle)) * dot(k, x)) * k;
}

/// Where the flow of the twist (v, w, O) takes p in h seconds (w != 0).
Vec3 flowImage(const Vec3& v, const Vec3& w, const Vec3& o, double h, const Vec3& p) {
  const double w2 = dot(w, w);
  const Vec3 axis_point = o + (1.0 / w2) * cross(w, v);
  const Vec3 v_par = (dot(v, w) / w2) * w;
  return axis_point + rotated((1.0 / std::sqrt(w2)) * w, std::sqrt(w2) * h, p - axis_point) +
         h * v_par;
}

Vec3 unitVector(const Vec3& a) {
  return (1.0 / norm(a)) * a;
}

/// Expects p + h c_t to land on `image` for two normals orthogonal to the displacement (the
/// tangential part then keeps the whole of a right c; a wrong c cannot hide along both).
void expectLands(const StepLaw& law, const Vec3& p, double h, const Vec3& image) {
  const Vec3 move = image - p;
  const Vec3 n1 =
      unitVector(cross(move, std::fabs(move.x) < 0.5 * norm(move) ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
  const Vec3 n2 = unitVector(cross(move, n1));
  for (const Vec3& n : {n1, n2}) {
    const Vec3 landed = p + h * law.tangentialVelocity(p, n);
    EXPECT_NEAR(landed.x, image.x, kLandingTolerance);
    EXPECT_NEAR(landed.y, image.y, kLandingTolerance);
    EXPECT_NEAR(landed.z, image.z, kLandingTolerance);
  }
}

const Vec3 kPoints[] = {{0.1, 0, 0}, {0.7, -0.3, 0.2}, {-0.4, 0.9, -0.6}, {0.2, 0.1, 0.05}};

}  // namespace

TEST(SecantLaw, PointCarriedOverTheStepLandsOnTheRotatedPoint) {
  const Vec3 o{0.2, -0.1, 0.05};
  const Vec3 axis = unitVector({0.3, -0.4, 1.2});
  for (double speed : {1.0, 5.0, 50.0}) {        // rad/s
    for (double h : {1e-4, 1e-3, 0.01, 0.05}) {  // s: turns of 1e-4 to 2.5 rad
      const Vec3 w = speed * axis;
      const StepLaw law = MotionLaw::rotation(w, o).evaluate(0, nullptr, h);
      for (const Vec3& p : kPoints) {
        SCOPED_TRACE(testing::Message() << "|w| = " << speed << ", h = " << h << ", p = (" << p.x
                                        << ", " << p.y << ", " << p.z << ")");
        expectLands(law, p, h, o + rotated(axis, speed * h, p - o));
      }
    }
  }
}

TEST(SecantLaw, ScrewTwistCarriesAPointAlongItsHelix) {
  // v has parts along w (the screw's advance) and across it (moves the axis to O').
  const Vec3 v{0.1, 0.2, -0.3}, o{-0.2, 0.3, 0.1};
  for (const Vec3& w : {Vec3{0, 0, 2.0}, Vec3{1.5, -0.5, 3.0}}) {
    for (double h : {1e-3, 0.01, 0.05}) {
      const StepLaw law = MotionLaw::twist({v, w, o}).evaluate(0, nullptr, h);
      for (const Vec3& p : kPoints) {
        SCOPED_TRACE(testing::Message() << "h = " << h << ", p.x = " << p.x);
        expectLands(law, p, h, flowImage(v, w, o, h, p));
      }
    }
  }
  // The helix advances by h v_par along the axis, whatever the turn: for w along z, the height
  // of the landed point grows by h v_z.
  const StepLaw law = MotionLaw::twist({v, {0, 0, 2.0}, o}).evaluate(0, nullptr, 0.05);
  const Vec3 p{0.7, -0.3, 0.2};
  const Vec3 c = law.tangentialVelocity(p, unitVector({1, 1, 0}));  // z is tangential here
  EXPECT_NEAR(c.z, v.z, kRoundOff);
}

TEST(SecantLaw, SecantTendsToTheTangentAsTheStepShrinks) {
  // The secant of a smooth path over h is its velocity plus h/2 its acceleration plus O(h^2):
  // c_h = c_0 + (h/2) w x c_0 + e, |e| <= (h^2/6) |w|^2 |c_0| (1 + |w| h) (each derivative of
  // the path is w x the previous one, so the k-th is at most |w|^(k-1) |c_0|, and the Taylor
  // tail from h^3/24 on is below |w| h times the h^2/6 term). Normal: orthogonal to c_0 and
  // w x c_0, so both are wholly tangential.
  const Vec3 v{0.1, 0.2, -0.3}, w{1.5, -0.5, 3.0}, o{-0.2, 0.3, 0.1}, p{0.7, -0.3, 0.2};
  const MotionLaw law = MotionLaw::twist({v, w, o});
  const Vec3 c0 = v + cross(w, p - o);
  const Vec3 accel = cross(w, c0);
  const Vec3 n = unitVector(cross(c0, accel));
  const double w2 = dot(w, w);
  for (double h : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6}) {
    SCOPED_TRACE(h);
    const Vec3 c = law.evaluate(0, nullptr, h).tangentialVelocity(p, n);
    const Vec3 e = c - c0 - (0.5 * h) * accel;
    // Plus the round-off of c (16 digits of |c_0| ~ 1 m/s).
    EXPECT_LE(norm(e), h * h / 6 * w2 * norm(c0) * (1 + std::sqrt(w2) * h) + 10 * kRoundOff);
  }
  // And the secant really differs from the tangent at a large step (the test can fail).
  EXPECT_GT(norm(law.evaluate(0, nullptr, 0.05).tangentialVelocity(p, n) - c0), 0.01);
}

TEST(SecantLaw, StepZeroIsBitwiseTheInstantaneousField) {
  const Vec3 v{0.1, 0.2, -0.3}, w{1.5, -0.5, 3.0}, o{-0.2, 0.3, 0.1};
  const StepLaw law = MotionLaw::twist({v, w, o}).evaluate(0, nullptr, 0.0);
  const Vec3 n = unitVector({0.2, -0.1, 1.0});
  for (const Vec3& p : kPoints) {
    const Vec3 expected = tangentialPart(v + cross(w, p - o), n);
    const Vec3 c = law.tangentialVelocity(p, n);
    EXPECT_EQ(c.x, expected.x);
    EXPECT_EQ(c.y, expected.y);
    EXPECT_EQ(c.z, expected.z);
    const Vec3 carried = law.tangentialVelocity(p, n, {0.5, 0.5, 0.5});
    EXPECT_EQ(carried.x, expected.x);
    EXPECT_EQ(carried.y, expected.y);
    EXPECT_EQ(carried.z, expected.z);
  }
}

TEST(SecantLaw, TranslationBeltAndFieldDoNotDependOnTheStep) {
  const Vec3 n = unitVector({0.2, -0.1, 1.0});
  const MotionLaw laws[] = {MotionLaw::translation({0.3, -0.2, 0.1}),
                            MotionLaw::belt({1, 2, 0}, 0.4),
                            MotionLaw::field([](const Vec3& p, const Vec3&, double) {
                              return Vec3{-p.y, p.x, 0};
                            })};
  for (const MotionLaw& law : laws) {
    const StepLaw instant = law.evaluate(0.5, nullptr, 0.0);
    const StepLaw stepped = law.evaluate(0.5, nullptr, 0.05);
    EXPECT_TRUE(instant.sameMotionAs(stepped));
    for (const Vec3& p : kPoints) {
      const Vec3 a = instant.tangentialVelocity(p, n), b = stepped.tangentialVelocity(p, n);
      EXPECT_EQ(a.x, b.x);
      EXPECT_EQ(a.y, b.y);
      EXPECT_EQ(a.z, b.z);
    }
  }
}

TEST(SecantLaw, BodyFrameAndTwistFunctionFreezeToAWorldTwistFirst) {
  // Body frame (turnedPose): body twist v = (0.1, 0, 0), w = (2, 0, 0) about (0.5, 0, 0) is the
  // world twist v = (0, 0.1, 0), w = (0, 2, 0) about (1, 2.5, 3).
  const Pose pose = turnedPose();
  const double h = 0.05;
  const StepLaw body =
      MotionLaw::twist({{0.1, 0, 0}, {2, 0, 0}, {0.5, 0, 0}}, Frame::Body).evaluate(0, &pose, h);
  for (const Vec3& p : kPoints) {
    expectLands(body, p, h, flowImage({0, 0.1, 0}, {0, 2, 0}, {1, 2.5, 3}, h, p));
  }
  // A twist function, frozen at t = 2: w = (0, 0, t) about (t, 0, 0).
  const MotionLaw of_time = MotionLaw::twistFunction([](double t) {
    return Twist{{}, {0, 0, t}, {t, 0, 0}};
  });
  const StepLaw frozen = of_time.evaluate(2.0, nullptr, h);
  for (const Vec3& p : kPoints) {
    expectLands(frozen, p, h, flowImage({}, {0, 0, 2.0}, {2.0, 0, 0}, h, p));
  }
}

TEST(SecantLaw, CarriedFormMovesTheCentreOfMassOnItsSecantAndThePartRigidly) {
  // For a part with centre of mass x_c, every contact asks for the rigid motion that takes x_c
  // to its image and turns at w: c(p) - c(q) = w x (p - q), and x_c + h c(x_c) = image(x_c).
  const Vec3 v{0.1, 0.2, -0.3}, w{1.5, -0.5, 3.0}, o{-0.2, 0.3, 0.1};
  const double h = 0.05;
  const StepLaw law = MotionLaw::twist({v, w, o}).evaluate(0, nullptr, h);
  const Vec3 centre{0.3, 0.2, 0.1};
  const Vec3 n = unitVector({0.2, -0.1, 1.0});
  const Vec3 image = flowImage(v, w, o, h, centre);
  const Vec3 moved = centre + h * law.tangentialVelocity(
                                      centre, unitVector(cross(image - centre, {0, 0, 1})), centre);
  EXPECT_NEAR(moved.x, image.x, kLandingTolerance);
  EXPECT_NEAR(moved.y, image.y, kLandingTolerance);
  EXPECT_NEAR(moved.z, image.z, kLandingTolerance);
  for (const Vec3& p : kPoints) {
    const Vec3 rigid =
        tangentialPart(law.tangentialVelocity(centre, n, centre) + cross(w, p - centre), n);
    expectVec(law.tangentialVelocity(p, n, centre), rigid.x, rigid.y, rigid.z, 10 * kRoundOff);
    // carried = p is the point's own secant.
    const Vec3 own = law.tangentialVelocity(p, n);
    const Vec3 self = law.tangentialVelocity(p, n, p);
    EXPECT_EQ(own.x, self.x);
    EXPECT_EQ(own.y, self.y);
    EXPECT_EQ(own.z, self.z);
  }
}

TEST(SecantLaw, BadStepGivesANonFiniteLawNamingIt) {
  const MotionLaw law = MotionLaw::rotation({0, 0, 1}, {0, 0, 0});
  for (double step :
       {-0.01, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    const StepLaw frozen = law.evaluate(0, nullptr, step);
    EXPECT_FALSE(frozen.finite());
    EXPECT_NE(frozen.problem().find("step = "), std::string::npos) << frozen.problem();
  }
  EXPECT_NE(law.evaluate(0, nullptr, -0.01).problem().find("-0.01"), std::string::npos);
}

TEST(SecantLaw, ADifferentStepIsADifferentMotion) {
  const MotionLaw law = MotionLaw::rotation({0, 0, 1}, {0, 0, 0});
  EXPECT_TRUE(law.evaluate(0, nullptr, 0.01).sameMotionAs(law.evaluate(1, nullptr, 0.01)));
  EXPECT_FALSE(law.evaluate(0, nullptr, 0.01).sameMotionAs(law.evaluate(0, nullptr, 0.02)));
  EXPECT_FALSE(law.evaluate(0, nullptr, 0.01).sameMotionAs(law.evaluate(0, nullptr, 0.0)));
}

}  // namespace rheofeed
