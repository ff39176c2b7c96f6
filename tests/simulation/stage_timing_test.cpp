// SPDX-License-Identifier: MIT
// Stage timing (simulation.hpp, StageTimes): off by default; when on it counts the steps, the
// contact joints and their constraint rows by ODE's rule for a contact joint (1 normal row, plus
// 2 friction rows when mu > 0: dxJointContact::getInfo1 of ODE 0.16) and the reference's cone
// (3 rows); it does not change a run. No test reads a time: the times are the benchmark's
// (crowd_scale_bench); here only the counts are checked.
#include <gtest/gtest.h>

#include <memory>

#include "common/builtin_scenes.hpp"
#include "rheofeed/simulation/simulation.hpp"
#include "scene_builders.hpp"

namespace rheofeed::scene {
namespace {

// A 2 cm cube resting on a floor for `steps` steps of 0.01 s, with friction coefficient `mu`.
Scene cubeOnFloor(double mu, int steps) {
  Scene s = test::cubeOnFloor("cube on floor", 0.01, steps * 0.01);
  s.material.mu = mu;
  return s;
}

TEST(StageTiming, IsOffByDefaultAndCountsNothing) {
  const auto sim = makeSimulation(cubeOnFloor(0.5, 10), Method::OdeRheonomic);
  for (int k = 0; k < 10; ++k) sim->step();
  const StageTimes& t = sim->stageTimes();
  EXPECT_EQ(t.steps, 0);
  EXPECT_EQ(t.contact_count, 0);
  EXPECT_EQ(t.constraint_rows, 0);
}

// The contact joints counted are the step's contacts of the cube with the floor (the only
// pair), which the simulation also reports in contactTotals(); a joint with friction has 3 rows,
// one without 1.
TEST(StageTiming, CountsTheTimedStepsAndTheContactRowsOfOdeJoints) {
  for (const double mu : {0.5, 0.0}) {
    const auto sim = makeSimulation(cubeOnFloor(mu, 30), Method::OdeRheonomic);
    for (int k = 0; k < 5; ++k) sim->step();  // not timed
    sim->setStageTiming(true);
    long contacts = 0;
    for (int k = 0; k < 20; ++k) {
      sim->step();
      contacts += sim->contactTotals().count;
    }
    sim->setStageTiming(false);
    for (int k = 0; k < 5; ++k) sim->step();  // not timed
    const StageTimes& t = sim->stageTimes();
    EXPECT_EQ(t.steps, 20);
    EXPECT_GT(contacts, 0) << "the cube rests on the floor";
    EXPECT_EQ(t.contact_count, contacts) << "mu = " << mu;
    EXPECT_EQ(t.constraint_rows, (mu > 0 ? 3 : 1) * contacts) << "mu = " << mu;
  }
}

// The reference engine does not split its step (its whole step is timed as the solve).
TEST(StageTiming, ReferenceEngineTimesItsWholeStepAsTheSolveWithThreeRowsPerContact) {
  const auto sim = makeSimulation(cubeOnFloor(0.5, 10), Method::ReferenceRheonomic);
  sim->setStageTiming(true);
  long contacts = 0;
  for (int k = 0; k < 10; ++k) {
    sim->step();
    contacts += sim->contactTotals().count;
  }
  const StageTimes& t = sim->stageTimes();
  EXPECT_EQ(t.steps, 10);
  EXPECT_GT(contacts, 0);
  EXPECT_EQ(t.contact_count, contacts);
  EXPECT_EQ(t.constraint_rows, 3 * contacts);
}

// Timing only reads clocks: a timed run of the hopper-fed trough (parts in a heap, many pairs)
// ends in the same part states, bit for bit, as an untimed one.
TEST(StageTiming, DoesNotChangeTheRun) {
  Scene scene = linearTroughScene(30, 30);
  scene.solver.time_step = 0.01;
  scene.duration = 1.5;
  scene.outputs.warmup = 0;
  const auto plain = makeSimulation(scene, Method::OdeRheonomic);
  const auto timed = makeSimulation(scene, Method::OdeRheonomic);
  timed->setStageTiming(true);
  for (int k = 0; k < 150; ++k) {
    plain->step();
    timed->step();
  }
  ASSERT_EQ(plain->numParts(), 30);
  ASSERT_EQ(timed->numParts(), 30);
  for (int i = 0; i < plain->numParts(); ++i) {
    const PartState a = plain->part(i), b = timed->part(i);
    EXPECT_EQ(a.position.x, b.position.x) << "part " << i;
    EXPECT_EQ(a.position.y, b.position.y) << "part " << i;
    EXPECT_EQ(a.position.z, b.position.z) << "part " << i;
    EXPECT_EQ(a.velocity.x, b.velocity.x) << "part " << i;
  }
  EXPECT_EQ(timed->stageTimes().steps, 150);
  EXPECT_GT(timed->stageTimes().contact_count, 0);
}

}  // namespace
}  // namespace rheofeed::scene
