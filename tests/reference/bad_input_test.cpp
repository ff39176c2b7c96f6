// SPDX-License-Identifier: MIT
// Bad configuration is refused where it is made, with std::invalid_argument naming the value
// (STYLE.md, rule 7): World settings, step sizes, bodies, friction coefficients from the
// callback, feeder laws and kinematic motions. A refused step leaves the world as it was.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include "reference_fixture.hpp"

namespace rheofeed::reference::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kStep = 1e-3;  // s

/// Runs `f`, expects std::invalid_argument, returns its message ("" if none was thrown).
std::string refusal(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "threw another exception: " << e.what();
    return "";
  }
  ADD_FAILURE() << "accepted";
  return "";
}

/// Expects World(settings) to be refused with a message containing every one of `needles`.
void expectRefusedSettings(const Settings& settings, std::initializer_list<const char*> needles) {
  const std::string message = refusal([&] { World world(settings); });
  for (const char* needle : needles) RHEOFEED_EXPECT_CONTAINS(message, needle);
}

TEST(ReferenceBadInput, ConstructorRefusesBadSettingsNamingThem) {
  initOdeOnce();
  Settings s = defaultSettings();
  s.erp = kNaN;
  expectRefusedSettings(s, {"erp", "nan"});
  s = defaultSettings();
  s.erp = 1.5;
  expectRefusedSettings(s, {"erp", "1.5"});
  s = defaultSettings();
  s.cfm = -1e-5;
  expectRefusedSettings(s, {"cfm", "-1e-05"});
  s = defaultSettings();
  s.max_correcting_velocity = -1;
  expectRefusedSettings(s, {"max_correcting_velocity", "-1"});
  s = defaultSettings();
  s.surface_layer = kInf;
  expectRefusedSettings(s, {"surface_layer", "inf"});
  s = defaultSettings();
  s.max_contacts_per_pair = 0;
  expectRefusedSettings(s, {"max_contacts_per_pair", "0"});
  s = defaultSettings();
  s.default_mu = -0.5;
  expectRefusedSettings(s, {"default_mu", "-0.5"});
  s = defaultSettings();
  s.default_mu = kNaN;
  expectRefusedSettings(s, {"default_mu", "nan"});
  s = defaultSettings();
  s.gravity = {0, kNaN, -9.81};
  expectRefusedSettings(s, {"gravity"});
  s = defaultSettings();
  s.solver.tolerance = -1;
  expectRefusedSettings(s, {"solver", "tolerance", "-1"});
  s = defaultSettings();
  s.solver.coulomb_outer_iterations = -3;
  expectRefusedSettings(s, {"solver", "coulomb_outer_iterations", "-3"});
  s = defaultSettings();
  s.ipm_rounds = -1;
  expectRefusedSettings(s, {"ipm_rounds", "-1"});
  s = defaultSettings();
  s.ipm.max_outer_iterations = 0;
  expectRefusedSettings(s, {"ipm", "max_outer_iterations", "0"});
}

/// A box resting on the ground, in contact from the first step.
struct RestingBox {
  explicit RestingBox(const Settings& settings) : world(settings) {
    ground = addGround(world);
    box = addBox(world, 1.0, {0.1, 0.1, 0.1}, restingAt({0, 0, 0.05 - 1e-6}));
  }
  World world;
  dGeomID ground = nullptr;
  BoxBody box;
};

TEST(ReferenceBadInput, StepRefusesBadTimeStepAndLeavesTheWorldUnchanged) {
  initOdeOnce();
  RestingBox scene(defaultSettings());
  scene.world.step(kStep);
  const double t = scene.world.time();
  const BodyState before = scene.world.state(scene.box.id);
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { scene.world.step(0.0); }), "h = 0");
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { scene.world.step(-kStep); }), "h = -0.001");
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { scene.world.step(kNaN); }), "h = nan");
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { scene.world.step(kInf); }), "h = inf");
  EXPECT_EQ(scene.world.time(), t);
  const BodyState& after = scene.world.state(scene.box.id);
  EXPECT_EQ(after.position, before.position);
  EXPECT_EQ(after.linear_velocity, before.linear_velocity);
  EXPECT_NO_THROW(scene.world.step(kStep)) << "the world still works";
}

TEST(ReferenceBadInput, AddBodyRefusesBadMassAndInertiaNamingThem) {
  initOdeOnce();
  World world(defaultSettings());
  const auto good = boxInertia(1.0, 0.1, 0.1, 0.1);
  const BodyState s = restingAt({0, 0, 1});
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.addBody(-1.0, good.data(), s); }), "mass = -1");
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.addBody(0.0, good.data(), s); }), "mass = 0");
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.addBody(kNaN, good.data(), s); }), "mass = nan");
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.addBody(kInf, good.data(), s); }), "mass = inf");
  // Not positive definite: one negative principal moment.
  const double negative[9] = {1e-3, 0, 0, 0, 1e-3, 0, 0, 0, -1e-3};
  const std::string m1 = refusal([&] { world.addBody(1.0, negative, s); });
  RHEOFEED_EXPECT_CONTAINS(m1, "inertia");
  RHEOFEED_EXPECT_CONTAINS(m1, "-0.001");
  // Symmetric, positive diagonal, but indefinite (eigenvalues 3e-3 and -1e-3).
  const double indefinite[9] = {1e-3, 2e-3, 0, 2e-3, 1e-3, 0, 0, 0, 1e-3};
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.addBody(1.0, indefinite, s); }), "eigenvalue");
  // Singular (a zero moment).
  const double singular[9] = {1e-3, 0, 0, 0, 1e-3, 0, 0, 0, 0};
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.addBody(1.0, singular, s); }), "inertia");
  const double asymmetric[9] = {1e-3, 1e-4, 0, 0, 1e-3, 0, 0, 0, 1e-3};
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.addBody(1.0, asymmetric, s); }), "symmetric");
  double with_nan[9];
  for (int k = 0; k < 9; ++k) with_nan[k] = good[k];
  with_nan[4] = kNaN;
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.addBody(1.0, with_nan, s); }), "inertia[4]");
  BodyState bad_state = s;
  bad_state.linear_velocity.y = kNaN;
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.addBody(1.0, good.data(), bad_state); }),
                           "not finite");
  EXPECT_EQ(world.numBodies(), 0) << "nothing refused was added";
}

TEST(ReferenceBadInput, NegativeOrNanMuFromTheFrictionCallbackIsRefusedAtStep) {
  initOdeOnce();
  for (const double mu : {-0.5, kNaN}) {
    SCOPED_TRACE(mu);
    RestingBox scene(defaultSettings());
    scene.world.setFrictionCallback([mu](dGeomID, dGeomID) { return mu; });
    const BodyState before = scene.world.state(scene.box.id);
    const std::string message = refusal([&] { scene.world.step(kStep); });
    RHEOFEED_EXPECT_CONTAINS(message, "mu");
    RHEOFEED_EXPECT_CONTAINS(message, std::isnan(mu) ? "nan" : "-0.5");
    EXPECT_EQ(scene.world.time(), 0.0);
    EXPECT_EQ(scene.world.state(scene.box.id).position, before.position);
  }
}

// The friction callback runs inside ODE's dSpaceCollide: its exception must not unwind through
// ODE's C code. It comes out of step() after the collision pass, the step is not taken, and
// the world steps normally afterwards.
TEST(ReferenceBadInput, ExceptionFromTheFrictionCallbackComesOutOfStepNotThroughOde) {
  initOdeOnce();
  RestingBox scene(defaultSettings());
  bool fail = true;
  scene.world.setFrictionCallback([&fail](dGeomID, dGeomID) -> double {
    if (fail) throw std::runtime_error("friction table has no entry for this pair");
    return 0.5;
  });
  const BodyState before = scene.world.state(scene.box.id);
  try {
    scene.world.step(kStep);
    ADD_FAILURE() << "the callback's exception was swallowed";
  } catch (const std::runtime_error& e) {
    RHEOFEED_EXPECT_CONTAINS(std::string(e.what()), "no entry for this pair");
  }
  EXPECT_EQ(scene.world.time(), 0.0);
  EXPECT_EQ(scene.world.state(scene.box.id).position, before.position);
  fail = false;
  for (int i = 0; i < 100; ++i) scene.world.step(kStep);
  // Resting on the floor: still there (not fallen through), no contact lost.
  EXPECT_NEAR(scene.world.state(scene.box.id).position.z, before.position.z, 1e-3);
  EXPECT_GT(scene.world.contacts().size(), 0u);
}

TEST(ReferenceBadInput, FeederLawsWithNanAreRefusedNamingTheValue) {
  initOdeOnce();
  RestingBox scene(defaultSettings());
  World& world = scene.world;
  // Refused when set.
  RHEOFEED_EXPECT_CONTAINS(refusal([&] {
                             world.setFeeder(scene.ground, MotionLaw::belt({1, 0, 0}, kNaN));
                           }),
                           "nan");
  RHEOFEED_EXPECT_CONTAINS(refusal([&] {
                             world.setFeeder(scene.ground, MotionLaw::translation({kNaN, 0, 0}));
                           }),
                           "nan");
  RHEOFEED_EXPECT_CONTAINS(
      refusal([&] {
        world.setFeeder(scene.ground, MotionLaw::rotation({0, 0, 1}, {0, kInf, 0}));
      }),
      "inf");
  // A law that turns non-finite only at run time is refused by the step that meets it.
  world.setFeeder(scene.ground,
                  MotionLaw::belt({1, 0, 0}, 0.5).withProfile(TimeProfile::function([](double t) {
                    return t < 2 * kStep ? 1.0 : kNaN;
                  })));
  world.step(kStep);
  world.step(kStep);
  const double t = world.time();
  const std::string message = refusal([&] { world.step(kStep); });
  RHEOFEED_EXPECT_CONTAINS(message, "not finite");
  RHEOFEED_EXPECT_CONTAINS(message, "nan");
  EXPECT_EQ(world.time(), t);
  world.setFeeder(scene.ground, MotionLaw::twistFunction([](double) {
                    Twist tw;
                    tw.linear = {0, kNaN, 0};
                    return tw;
                  }));
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.step(kStep); }), "nan");
}

TEST(ReferenceBadInput, KinematicMotionWithNanIsRefused) {
  initOdeOnce();
  World world(defaultSettings());
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.addKinematicBody(MotionOfTime{}); }), "empty");
  RHEOFEED_EXPECT_CONTAINS(refusal([&] {
                             world.addKinematicBody([](double) {
                               Pose p;
                               p.position.x = kNaN;
                               return p;
                             });
                           }),
                           "not finite");
  // Finite at t = 0, NaN from t = 1 ms on: the step that needs it is refused.
  const BodyId plate = world.addKinematicBody([](double t) {
    Pose p;
    p.position.x = t < 0.5 * kStep ? 0.0 : kNaN;
    return p;
  });
  EXPECT_EQ(plate, 0);
  const std::string message = refusal([&] { world.step(kStep); });
  RHEOFEED_EXPECT_CONTAINS(message, "kinematic body 0");
  RHEOFEED_EXPECT_CONTAINS(message, "t = 0.001");
  RHEOFEED_EXPECT_CONTAINS(message, "nan");
  EXPECT_EQ(world.time(), 0.0);
}

TEST(ReferenceBadInput, ForcesAndAttachmentsAreChecked) {
  initOdeOnce();
  RestingBox scene(defaultSettings());
  World& world = scene.world;
  RHEOFEED_EXPECT_CONTAINS(refusal([&] {
                             world.addForce(scene.box.id, {kNaN, 0, 0});
                           }),
                           "not finite");
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.addForce(7, {1, 0, 0}); }), "body 7");
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.attachGeom(scene.box.geom, scene.box.id); }),
                           "already attached");
  dGeomID extra = dCreateSphere(world.space(), 0.1);
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.attachGeom(extra, 3); }), "body 3");
  dSpaceID other = dSimpleSpaceCreate(nullptr);
  dGeomID outside = dCreateSphere(other, 0.1);
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { world.attachGeom(outside, scene.box.id); }), "space");
  dSpaceDestroy(other);
}

// Settings reached through World::settings() after construction must take effect and be
// checked like the constructor's.
TEST(ReferenceBadInput, SettingsChangedAfterConstructionAreCheckedAtStep) {
  initOdeOnce();
  RestingBox scene(defaultSettings());
  scene.world.settings().erp = kNaN;
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { scene.world.step(kStep); }), "erp = nan");
  EXPECT_EQ(scene.world.time(), 0.0);
  scene.world.settings().erp = 2.0;  // finite, but ODE's ERP is a fraction in [0, 1]
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { scene.world.step(kStep); }), "erp = 2");
  scene.world.settings().erp = 0.2;
  scene.world.settings().cfm = -1.0;
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { scene.world.step(kStep); }), "cfm = -1");
  scene.world.settings().cfm = 1e-5;
  // Also without any contact, where the value would otherwise go unnoticed.
  World empty(defaultSettings());
  empty.settings().gravity.z = kNaN;
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { empty.step(kStep); }), "gravity");
  scene.world.settings().erp = 0.2;
  scene.world.settings().solver.max_iterations = 0;
  RHEOFEED_EXPECT_CONTAINS(refusal([&] { scene.world.step(kStep); }), "max_iterations = 0");
  scene.world.settings().solver.max_iterations = 10000;
  EXPECT_NO_THROW(scene.world.step(kStep));
}

TEST(ReferenceBadInput, SolverSettingsChangedAfterConstructionTakeEffect) {
  initOdeOnce();
  // A sliding block: switching on the true-Coulomb mode through World::settings() must remove
  // the relaxation's separation velocity mu |u_t| (sliding_test.cpp).
  Settings settings = defaultSettings();
  settings.default_mu = 0.3;
  World world(settings);
  addGround(world);
  BodyState s = restingAt({0, 0, 0.05});
  s.linear_velocity = {1, 0, 0};
  const BoxBody box = addBox(world, 1.0, {0.1, 0.1, 0.1}, s);
  world.settings().solver.coulomb_outer_iterations = 50;
  const StepReport report = world.step(kStep);
  // The Coulomb law was solved (the default Coulomb solver is NSGS): its residual, which the
  // relaxed problem's separation at mu |u_t| would leave near 1, met the tolerance.
  EXPECT_EQ(report.solve.status, ccp::Status::Converged);
  EXPECT_LE(report.coulomb_residual, world.settings().solver.tolerance)
      << "the Coulomb mode was not used";
  // The relaxed problem would launch the block at ~mu |u_t| = 0.3 m/s.
  EXPECT_LT(std::abs(world.state(box.id).linear_velocity.z), 1e-3);
}

}  // namespace
}  // namespace rheofeed::reference::test
