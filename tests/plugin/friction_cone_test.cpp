// SPDX-License-Identifier: MIT
// The friction cone of the patched ODE (patches/0002, friction_model.hpp) against mechanics:
// Coulomb friction is isotropic, so
//   - a box pulled along a diagonal of ODE's friction axes starts to slide when the pull exceeds
//     mu m g (the pyramid holds it up to sqrt(2) mu m g), and slides with friction mu m g;
//   - a box sliding on a plane slows at mu g in every direction, along a straight line (the
//     pyramid slows a diagonal slide at sqrt(2) mu g);
//   - on a belt (fdir1 / motion1 along the belt) the slip relative to the belt decays at mu g
//     along its own direction, whatever that is: the rows keep motion1 as their target;
//   - dWorldStep (Dantzig) refuses a contact that asks for the cone, with an ODE message.
// On a stock ODE (RHEOFEED_ODE=system) the cone is refused where it is asked for, naming the
// setting; the mechanics tests of the cone do not apply there and say so.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "ode_world.hpp"
#include "rheofeed/friction_model.hpp"
#include "rheofeed/rheofeed.h"

#ifndef RHEOFEED_TEST_ODE_HAS_CONE
#error "the build defines RHEOFEED_TEST_ODE_HAS_CONE (0 or 1: the ODE this test is linked with)"
#endif

namespace rheofeed::test {
namespace {

constexpr bool kBuiltWithCone = RHEOFEED_TEST_ODE_HAS_CONE != 0;
constexpr double kStep = 0.001;  // s
constexpr double kMu = 0.4;
constexpr double kMass = 1.0;     // kg
constexpr double kEdge = 0.1;     // m, cube
constexpr double kLayer = 1e-4;   // m, contact surface layer (parts start in resting contact)
constexpr int kIterations = 100;  // quickstep sweeps: converged for one box on four contacts
// The diagonal of ODE's friction axes: for the normal +z, dPlaneSpace gives t1 = -y, t2 = +x.
constexpr double kDiagonal = kPi / 4;

// Friction measured from the motion, f = F - m a, relative to mu m g: quickstep at 100 sweeps
// and semi-implicit Euler leave well under 1 % on a sliding box (CFM 1e-9, ERP 0.2).
constexpr double kFrictionTolerance = 0.01;
// Stuck: the box moves less than this (m) in 0.3 s under a pull below the limit; sliding under
// 5 % more than the limit moves it 0.05 mu g t^2 / 2 = 1e-3 m in that time.
constexpr double kStuck = 1e-5;
// Straight line: the velocity turns by less than this (rad) while a slide decays.
constexpr double kStraight = 1e-3;

#define RHEOFEED_REQUIRE_CONE()                                                             \
  if (!kBuiltWithCone) {                                                                    \
    GTEST_SKIP() << "linked with a stock ODE (RHEOFEED_ODE=system): no friction cone; the " \
                    "refusal is FrictionCone.StockOdeRefusesTheConeNamingTheSetting";       \
  }

/// A static floor (top at z = 0) and a cube resting on it, stepped with dWorldQuickStep; every
/// contact gets Approx1 friction mu and the friction model `model`.
struct Floor {
  explicit Floor(FrictionModel model, bool driven_belt = false, double belt_speed = 0.0)
      : w(options(model), settings(model)) {
    dWorldSetContactSurfaceLayer(w.world, kLayer);
    dWorldSetQuickStepNumIterations(w.world, kIterations);
    const int mode = withFrictionModel(dContactApprox1, model);
    w.collider->setSurfaceCallback([mode](dGeomID, dGeomID, dContact* c, int n) {
      for (int i = 0; i < n; ++i) {
        c[i].surface = {};
        c[i].surface.mode = mode;
        c[i].surface.mu = kMu;
      }
      return true;
    });
    floor = w.staticBox(10.0, 10.0, 0.1, 0, 0, -0.05);
    part = w.box(kEdge, kEdge, kEdge, kMass, 0, 0, kEdge / 2 - kLayer);
    if (driven_belt) w.feeders->add(floor, MotionLaw::belt({1, 0, 0}, belt_speed));
  }
  static FeederSet::Options options(FrictionModel model) {
    FeederSet::Options o;
    o.friction = model;
    return o;
  }
  static ContactCollider::Settings settings(FrictionModel model) {
    ContactCollider::Settings s;
    s.friction = model;
    return s;
  }
  /// Steps for `duration` s with a horizontal force `force` (N) at angle `angle` (rad, from +x).
  void pull(double force, double angle, double duration) {
    const int n = static_cast<int>(duration / kStep + 0.5);
    for (int i = 0; i < n; ++i) {
      dBodyAddForce(part, force * std::cos(angle), force * std::sin(angle), 0);
      w.step(kStep, true);
    }
  }
  OdeWorld w;
  dGeomID floor;
  dBodyID part;
};

double horizontalSpeed(const Vec3& v) {
  return std::hypot(v.x, v.y);
}

// The friction force on a box pulled by F at `angle`, measured from its acceleration along the
// pull over 0.2 s after 0.1 s of start-up: f = F - m a, in units of mu m g.
double measuredFriction(FrictionModel model, double pull_in_mu_m_g, double angle) {
  Floor f(model);
  const double force = pull_in_mu_m_g * kMu * kMass * kGravity;
  f.pull(force, angle, 0.1);
  const Vec3 v0 = linearVelocity(f.part);
  f.pull(force, angle, 0.2);
  const Vec3 v1 = linearVelocity(f.part);
  const double a = ((v1.x - v0.x) * std::cos(angle) + (v1.y - v0.y) * std::sin(angle)) / 0.2;
  return (force - kMass * a) / (kMu * kMass * kGravity);
}

// How far a box pulled by F at `angle` moves in 0.3 s (m).
double displacementUnderPull(FrictionModel model, double pull_in_mu_m_g, double angle) {
  Floor f(model);
  const Vec3 x0 = position(f.part);
  f.pull(pull_in_mu_m_g * kMu * kMass * kGravity, angle, 0.3);
  const Vec3 x1 = position(f.part);
  return std::hypot(x1.x - x0.x, x1.y - x0.y);
}

TEST(FrictionCone, BuildAndLibraryAgreeOnTheCone) {
  // The ODE this binary runs with is the one CMake built it for (patched or stock).
  EXPECT_EQ(odeHasFrictionCone(), kBuiltWithCone) << dGetConfiguration();
  EXPECT_EQ(rfOdeHasFrictionCone(), kBuiltWithCone ? 1 : 0);
}

TEST(FrictionCone, StockOdeRefusesTheConeNamingTheSetting) {
  if (kBuiltWithCone) {
    GTEST_SKIP() << "linked with the patched ODE: the cone is accepted (the other tests here)";
  }
  FeederSet::Options o;
  o.friction = FrictionModel::Cone;
  try {
    FeederSet set(o);
    FAIL() << "a FeederSet with the cone was accepted on a stock ODE";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("Options::friction"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("ODE_EXT_friction_cone"), std::string::npos);
  }
  FeederSet set;
  EXPECT_THROW(set.setFrictionModel(FrictionModel::Cone), std::invalid_argument);
  EXPECT_EQ(set.frictionModel(), FrictionModel::Pyramid);
  OdeWorld w;
  ContactCollider::Settings s;
  s.friction = FrictionModel::Cone;
  EXPECT_THROW(ContactCollider(w.world, *w.feeders, s), std::invalid_argument);
  // The C API returns the error with the message.
  rfFeederSetID c = rfFeederSetCreate();
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(rfFeederSetSetFrictionModel(c, rfFrictionCone), rfErrorInvalidArgument);
  EXPECT_NE(std::string(rfFeederSetGetLastError(c)).find("friction"), std::string::npos);
  rfFeederSetDestroy(c);
}

TEST(FrictionCone, SurfaceCallbackAskingForTheConeOnStockOdeIsAnError) {
  if (kBuiltWithCone) GTEST_SKIP() << "linked with the patched ODE: the bit is honoured";
  Floor f(FrictionModel::Pyramid);
  f.w.collider->setSurfaceCallback([](dGeomID, dGeomID, dContact* c, int n) {
    for (int i = 0; i < n; ++i) c[i].surface.mode |= kContactFrictionCone;
    return true;
  });
  EXPECT_THROW(f.w.collider->collide(f.w.space, 0.0, kStep), std::invalid_argument);
}

TEST(FrictionCone, DiagonalPullSlidesAboveMuAndSticksBelow) {
  RHEOFEED_REQUIRE_CONE();
  EXPECT_LT(displacementUnderPull(FrictionModel::Cone, 0.95, kDiagonal), kStuck);
  EXPECT_GT(displacementUnderPull(FrictionModel::Cone, 1.05, kDiagonal), 100 * kStuck);
  // Along an axis both models hold up to mu exactly.
  EXPECT_LT(displacementUnderPull(FrictionModel::Cone, 0.95, 0.0), kStuck);
  EXPECT_GT(displacementUnderPull(FrictionModel::Cone, 1.05, 0.0), 100 * kStuck);
}

TEST(FrictionCone, PyramidHoldsADiagonalPullUpToSqrt2Mu) {
  // The defect the cone removes, measured on whichever ODE is linked.
  EXPECT_LT(displacementUnderPull(FrictionModel::Pyramid, 1.35, kDiagonal), kStuck);
  EXPECT_GT(displacementUnderPull(FrictionModel::Pyramid, 1.5, kDiagonal), 100 * kStuck);
  EXPECT_GT(displacementUnderPull(FrictionModel::Pyramid, 1.05, 0.0), 100 * kStuck);
}

TEST(FrictionCone, SlidingFrictionIsMuMgInEveryPullDirection) {
  RHEOFEED_REQUIRE_CONE();
  for (double deg : {0.0, 20.0, 45.0, 70.0, 135.0}) {
    const double angle = deg * kPi / 180;
    EXPECT_NEAR(measuredFriction(FrictionModel::Cone, 1.3, angle), 1.0, kFrictionTolerance)
        << "pull at " << deg << " deg";
  }
  // The pyramid at 45 degrees: still stuck at 1.3 mu m g (friction = the pull).
  EXPECT_NEAR(measuredFriction(FrictionModel::Pyramid, 1.3, kDiagonal), 1.3, kFrictionTolerance);
}

// A box launched at v0 along `angle` on a still floor; returns (speed after t, turn of the
// velocity in rad).
std::pair<double, double> slide(FrictionModel model, double angle, double v0, double t) {
  Floor f(model);
  dBodySetLinearVel(f.part, v0 * std::cos(angle), v0 * std::sin(angle), 0);
  f.pull(0.0, 0.0, t);
  const Vec3 v = linearVelocity(f.part);
  const double turn = std::fabs(std::remainder(std::atan2(v.y, v.x) - angle, 2 * kPi));
  return {horizontalSpeed(v), turn};
}

TEST(FrictionCone, SlidingPartSlowsAtMuGInEveryDirection) {
  RHEOFEED_REQUIRE_CONE();
  const double v0 = 1.0, t = 0.15;  // m/s, s: stops after v0 / (mu g) = 0.255 s
  const double expected = v0 - kMu * kGravity * t;
  for (double deg : {0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 200.0}) {
    const auto [speed, turn] = slide(FrictionModel::Cone, deg * kPi / 180, v0, t);
    // Deceleration within 1 % of mu g.
    EXPECT_NEAR((v0 - speed) / t, kMu * kGravity, kFrictionTolerance * kMu * kGravity)
        << "slide at " << deg << " deg";
    EXPECT_NEAR(speed, expected, kFrictionTolerance * kMu * kGravity * t);
    EXPECT_LT(turn, kStraight) << "slide at " << deg << " deg";
  }
}

TEST(FrictionCone, PyramidSlowsADiagonalSlideAtSqrt2MuG) {
  const double v0 = 1.0, t = 0.15;
  const auto [speed, turn] = slide(FrictionModel::Pyramid, kDiagonal, v0, t);
  EXPECT_NEAR((v0 - speed) / t, std::sqrt(2.0) * kMu * kGravity,
              kFrictionTolerance * kMu * kGravity);
  (void)turn;
}

TEST(FrictionCone, SlipOnABeltDecaysAtMuGAlongItsOwnDirection) {
  RHEOFEED_REQUIRE_CONE();
  // The belt drives along +x at V (fdir1 = +x, motion1 = V); the part starts with a slip s0 at
  // `angle` relative to the belt surface. Coulomb: the slip shrinks at mu g along a straight
  // line, so the part reaches the belt's velocity after s0 / (mu g) whatever the angle.
  const double belt = 0.3, s0 = 0.5, t = 0.08;  // m/s, m/s, s (stops at 0.127 s)
  for (double deg : {0.0, 30.0, 60.0, 90.0, 150.0}) {
    const double angle = deg * kPi / 180;
    Floor f(FrictionModel::Cone, true, belt);
    dBodySetLinearVel(f.part, belt + s0 * std::cos(angle), s0 * std::sin(angle), 0);
    f.pull(0.0, 0.0, t);
    const Vec3 v = linearVelocity(f.part);
    const double sx = v.x - belt, sy = v.y;
    EXPECT_NEAR(std::hypot(sx, sy), s0 - kMu * kGravity * t,
                kFrictionTolerance * kMu * kGravity * t)
        << "slip at " << deg << " deg";
    EXPECT_LT(std::fabs(std::remainder(std::atan2(sy, sx) - angle, 2 * kPi)), kStraight)
        << "slip at " << deg << " deg";
  }
}

TEST(FrictionCone, DantzigStepRefusesTheCone) {
  RHEOFEED_REQUIRE_CONE();
  Floor f(FrictionModel::Cone);
  dBodySetLinearVel(f.part, 0.5, 0, 0);
  const Vec3 before = position(f.part);
  OdeMessageGuard guard(OdeMessageGuard::Policy::Record);
  f.w.collider->collide(f.w.space, 0.0, kStep);
  EXPECT_EQ(dWorldStep(f.w.world, kStep), 0);
  ASSERT_EQ(guard.messages().size(), 1u);
  EXPECT_EQ(guard.messages()[0].kind, OdeMessageGuard::Kind::Message);
  EXPECT_NE(guard.messages()[0].text.find("dContactFrictionCone"), std::string::npos)
      << guard.messages()[0].text;
  const Vec3 after = position(f.part);
  EXPECT_EQ(after.x, before.x) << "the refused step moved the part";
  // Without the flag dWorldStep steps as always.
  f.w.collider->clearJoints();
  EXPECT_EQ(dWorldStep(f.w.world, kStep), 1);
}

}  // namespace
}  // namespace rheofeed::test
