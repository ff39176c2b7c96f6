// SPDX-License-Identifier: MIT
// Settings::ipm_rounds: a step NSGS leaves unconverged (here: a budget of one sweep) is solved
// again by the interior-point fixed point and NSGS in turn, and the step's motion is Coulomb's
// (a box sliding on the ground decelerates at mu g); where the rounds cannot run the step says
// why (StepReport::ipm_not_run) instead of keeping NSGS's iterate silently.
#include <gtest/gtest.h>

#include <string>

#include "reference_fixture.hpp"

namespace rheofeed::reference::test {
namespace {

constexpr double kStep = 0.01;  // s
constexpr double kSpeed = 0.5;  // m/s, the box's initial slide along x
constexpr double kMass = 1.0;   // kg
constexpr double kEdge = 0.1;   // m

/// NSGS with one sweep and no global Newton steps: it cannot settle four sliding corners.
Settings oneSweepSettings() {
  Settings s = coulombSettings();
  s.nsgs.max_iterations = 1;
  s.nsgs.global_newton_interval = 0;
  return s;
}

/// One step of a 10 cm box sliding at kSpeed on the ground, in contact from the start, in a
/// world of these settings.
struct SlideOneStep {
  explicit SlideOneStep(const Settings& settings) : world(settings) {
    addGround(world);
    BodyState state = restingAt({0, 0, 0.5 * kEdge - 1e-6});
    state.linear_velocity = {kSpeed, 0, 0};
    box = addBox(world, kMass, {kEdge, kEdge, kEdge}, state);
    report = world.step(kStep);
  }
  bool ode_ready = (initOdeOnce(), true);  // before the world
  World world;
  BoxBody box;
  StepReport report;
};

TEST(ReferenceIpmRounds, ConvergeWhatOneSweepLeavesAndGiveCoulombsDeceleration) {
  Settings alone = oneSweepSettings();
  alone.ipm_rounds = 0;
  const StepReport nsgs_only = SlideOneStep(alone).report;
  ASSERT_EQ(nsgs_only.contacts, 4);
  ASSERT_EQ(nsgs_only.solve.status, ccp::Status::MaxIterations) << "premise: one sweep is short";
  EXPECT_EQ(nsgs_only.ipm_rounds, 0);

  const Settings settings = oneSweepSettings();
  const SlideOneStep run(settings);
  const StepReport& report = run.report;
  EXPECT_EQ(report.solve.status, ccp::Status::Converged) << report.solve.message;
  EXPECT_GE(report.ipm_rounds, 1);
  EXPECT_TRUE(report.ipm_not_run.empty()) << report.ipm_not_run;
  // Coulomb: the box keeps sliding and loses mu g h of its speed, without hopping - up to what
  // the compliance (cfm / h times the weight's impulse m g h) and the push-out of the 1 um
  // start penetration (erp depth / h) allow the normal velocity, and mu times that the slide.
  const double slack = settings.cfm * kMass * kGravity + settings.erp * 1e-6 / kStep;  // m/s
  const BodyState& after = run.world.state(run.box.id);
  EXPECT_NEAR(after.linear_velocity.x, kSpeed - settings.default_mu * kGravity * kStep,
              settings.default_mu * slack);
  EXPECT_NEAR(after.linear_velocity.z, 0.0, slack);
}

TEST(ReferenceIpmRounds, AStepAboveTheContactLimitSaysTheRoundsDidNotRun) {
  Settings settings = oneSweepSettings();
  settings.ipm_max_contacts = 3;
  const StepReport report = SlideOneStep(settings).report;
  EXPECT_EQ(report.solve.status, ccp::Status::MaxIterations);
  EXPECT_EQ(report.ipm_rounds, 0);
  RHEOFEED_EXPECT_CONTAINS(report.ipm_not_run, "4 contacts, above ipm_max_contacts = 3");
}

TEST(ReferenceIpmRounds, AFrictionlessContactRefusedByTheInteriorPointMethodIsSaid) {
  Settings settings = oneSweepSettings();
  settings.default_mu = 0.0;
  const StepReport report = SlideOneStep(settings).report;
  ASSERT_EQ(report.solve.status, ccp::Status::MaxIterations) << "premise: one sweep is short";
  EXPECT_EQ(report.ipm_rounds, 0);
  RHEOFEED_EXPECT_CONTAINS(report.ipm_not_run, "has mu = 0");
}

}  // namespace
}  // namespace rheofeed::reference::test
