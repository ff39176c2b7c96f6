// SPDX-License-Identifier: MIT
// A body whose state becomes non-finite must not poison the run: it is disabled at its last
// finite pose and reported, and every other body steps on exactly as if it had not been there.
//
// Oracle: a twin world with the same bodies, no overflowing load, and the same body taken out by
// World::disableBody before the same step. (Not a twin that keeps it: the victim's contacts
// with the ground are part of the one contact problem of the step, and an iterative solve of a
// different problem differs at its tolerance even for unconnected bodies.) The other bodies'
// states must be bit-identical between the two worlds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "reference_fixture.hpp"

namespace rheofeed::reference::test {
namespace {

constexpr double kStep = 1e-3;  // s
constexpr int kSteps = 50;
constexpr double kHuge = 1e308;  // N m: finite; two of them sum to +inf

bool allFinite(const BodyState& s) {
  const double v[] = {s.position.x,        s.position.y,         s.position.z,
                      s.orientation.w,     s.orientation.x,      s.orientation.y,
                      s.orientation.z,     s.linear_velocity.x,  s.linear_velocity.y,
                      s.linear_velocity.z, s.angular_velocity.x, s.angular_velocity.y,
                      s.angular_velocity.z};
  return std::all_of(std::begin(v), std::end(v), [](double x) { return std::isfinite(x); });
}

struct Scene {
  World world{defaultSettings()};
  BoxBody resting, falling, victim;
  Scene() {
    addGround(world);
    resting = addBox(world, 1.0, {0.1, 0.1, 0.1}, restingAt({0, 0, 0.05}));
    falling = addBox(world, 1.0, {0.1, 0.1, 0.1}, restingAt({1, 0, 0.5}));
    victim = addBox(world, 1.0, {0.1, 0.1, 0.1}, restingAt({-1, 0, 0.05}));
  }
};

void expectSameState(const BodyState& a, const BodyState& b) {
  EXPECT_EQ(std::memcmp(&a, &b, sizeof(BodyState)), 0);
}

TEST(ReferenceNonFinite, OverflowingTorqueDisablesAndReportsOnlyThatBody) {
  initOdeOnce();
  Scene bad, twin;
  for (int k = 0; k < 10; ++k) {
    bad.world.step(kStep);
    twin.world.step(kStep);
  }
  const BodyState before = bad.world.state(bad.victim.id);
  // Each torque is finite (accepted); their sum overflows to +inf.
  bad.world.addForce(bad.victim.id, {}, {kHuge, 0, 0});
  bad.world.addForce(bad.victim.id, {}, {kHuge, 0, 0});
  const StepReport report = bad.world.step(kStep);
  twin.world.disableBody(twin.victim.id);
  twin.world.step(kStep);
  ASSERT_EQ(report.nonfinite_bodies.size(), 1u);
  EXPECT_EQ(report.nonfinite_bodies[0], bad.victim.id);
  // Disabled at its last finite pose, at rest.
  const BodyState& after = bad.world.state(bad.victim.id);
  EXPECT_TRUE(allFinite(after));
  EXPECT_EQ(after.position.z, before.position.z);
  EXPECT_EQ(norm(after.linear_velocity), 0.0);
  EXPECT_EQ(norm(after.angular_velocity), 0.0);
  for (int k = 0; k < kSteps; ++k) {
    const StepReport r = bad.world.step(kStep);
    EXPECT_TRUE(r.nonfinite_bodies.empty()) << "reported again at step " << k;
    twin.world.step(kStep);
  }
  expectSameState(bad.world.state(bad.resting.id), twin.world.state(twin.resting.id));
  expectSameState(bad.world.state(bad.falling.id), twin.world.state(twin.falling.id));
  EXPECT_EQ(bad.world.state(bad.victim.id).position.z, before.position.z);
}

TEST(ReferenceNonFinite, OverflowingForceOnATinyMassIsReportedNotThrown) {
  initOdeOnce();
  World world(defaultSettings());
  addGround(world);
  const BoxBody ok = addBox(world, 1.0, {0.1, 0.1, 0.1}, restingAt({0, 0, 0.05}));
  // 1e308 N on 1e-3 kg: the velocity change h F / m = 1e302 m/s is finite, but the next
  // position x + h v stays finite too; a second step with the same force overflows v.
  const BoxBody light = addBox(world, 1e-3, {0.01, 0.01, 0.01}, restingAt({1, 0, 0.5}));
  int reported = 0;
  for (int k = 0; k < 5; ++k) {
    world.addForce(light.id, {kHuge, 0, 0});
    const StepReport r = world.step(kStep);
    for (BodyId id : r.nonfinite_bodies) {
      EXPECT_EQ(id, light.id);
      ++reported;
    }
  }
  EXPECT_EQ(reported, 1);
  EXPECT_TRUE(allFinite(world.state(light.id)));
  EXPECT_TRUE(allFinite(world.state(ok.id)));
  EXPECT_NEAR(world.state(ok.id).position.z, 0.05, 1e-4);
}

}  // namespace
}  // namespace rheofeed::reference::test
