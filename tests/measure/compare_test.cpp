// SPDX-License-Identifier: MIT
// compare.cpp: runScene's end-of-run averages and compare's differences, on scenes whose answer
// is known without either engine: a cube resting on a floor (the normal impulse per step is
// its weight times the step, m g h) and a cube carried by a belt (it ends at the belt's speed).
// The differences compare reports are recomputed here from the states it returns.
#include "rheofeed/measure/compare.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scene_builders.hpp"

namespace rheofeed::scene {
namespace {

constexpr double kG = 9.81;         // m/s^2
constexpr double kEdge = 0.02;      // m, cube edge
constexpr double kDensity = 1000;   // kg/m^3
constexpr double kStep = 0.005;     // s
constexpr double kBeltSpeed = 0.3;  // m/s
// At rest the contact impulse balances the weight over a step. After 0.5 s at rest the
// iterative solves (ODE quickstep and the reference PGS, 50 iterations, warm-started) have
// converged: the residual is a few 1e-8 of m g h; 1e-6 leaves room for their rounding.
constexpr double kWeightBalance = 1e-6;  // relative
// The contact compliance (CFM 1e-5, ERP 0.2) lets the cube sink a few nanometres.
constexpr double kRestingSink = 1e-6;  // m
// A cube that sticks to the belt moves with it; the same solves leave a slip below 1e-7 m/s.
constexpr double kBeltSpeedError = 1e-5;  // m/s
// compare's maxima are recomputed from the same doubles: exact.
constexpr double kExact = 0;

Scene restingCube(const FeederLaw& floor_law = {}) {
  Scene s;
  s.name = "resting cube";
  Fixture floor = test::boxFixture("floor", {1, 1, 0.02});  // top at z = 0
  floor.law = floor_law;
  s.fixtures.push_back(floor);
  PartSpec p;
  p.name = "cube";
  for (auto& d : p.size) d.mean = kEdge;
  p.density = kDensity;
  p.spawn_min = p.spawn_max = {0, 0, 0.5 * kEdge};  // resting on the floor
  p.random_orientation = false;
  s.parts.push_back(p);
  s.solver.time_step = kStep;
  s.duration = 0.5;
  return s;
}

TEST(RunScene, AtRestTheNormalImpulsePerStepIsTheWeightTimesTheStep) {
  const double weight_impulse = kDensity * kEdge * kEdge * kEdge * kG * kStep;  // N s
  for (Method m : {Method::OdeRheonomic, Method::ReferenceRheonomic}) {
    SCOPED_TRACE(toString(m));
    const RunSummary r = runScene(restingCube(), m, 20);
    EXPECT_EQ(r.method, m);
    ASSERT_EQ(r.parts, 1);
    ASSERT_EQ(r.states.size(), 1u);
    EXPECT_NEAR(r.normal_impulse, weight_impulse, kWeightBalance * weight_impulse);
    EXPECT_NEAR(r.impulse.z, weight_impulse, kWeightBalance * weight_impulse);
    // The averages of one part are its state.
    EXPECT_EQ(r.mean_position, r.states[0].position);
    EXPECT_EQ(r.mean_velocity, r.states[0].velocity);
    EXPECT_NEAR(r.mean_position.z, 0.5 * kEdge, kRestingSink);  // still on the floor
  }
}

TEST(Compare, ABeltCarriesTheCubeAtItsSpeedInBothEnginesAndTheDifferencesAreTheStates) {
  FeederLaw belt;
  belt.kind = FeederLaw::Kind::Belt;
  belt.belt_direction = {1, 0, 0};
  belt.belt_speed = kBeltSpeed;
  const Scene s = restingCube(belt);
  const Comparison c = compare(s, Method::OdeRheonomic, Method::ReferenceRheonomic, 20);
  EXPECT_EQ(c.scene, s.name);
  EXPECT_NEAR(c.a.mean_velocity.x, kBeltSpeed, kBeltSpeedError);
  EXPECT_NEAR(c.b.mean_velocity.x, kBeltSpeed, kBeltSpeedError);
  ASSERT_EQ(c.a.states.size(), 1u);
  ASSERT_EQ(c.b.states.size(), 1u);
  const PartState& a = c.a.states[0];
  const PartState& b = c.b.states[0];
  EXPECT_NEAR(c.max_velocity_difference, norm(a.velocity - b.velocity), kExact);
  EXPECT_NEAR(c.max_position_difference, norm(a.position - b.position), kExact);
  EXPECT_NEAR(c.mean_velocity_difference, norm(c.a.mean_velocity - c.b.mean_velocity), kExact);
  const double j = std::max(std::abs(c.a.normal_impulse), std::abs(c.b.normal_impulse));
  EXPECT_NEAR(c.normal_impulse_difference, std::abs(c.a.normal_impulse - c.b.normal_impulse) / j,
              kExact);
  EXPECT_LT(c.max_velocity_difference, 2 * kBeltSpeedError);
}

}  // namespace
}  // namespace rheofeed::scene
