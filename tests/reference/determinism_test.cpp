// SPDX-License-Identifier: MIT
// Reproducibility: the same scene built twice in one process must give bit-identical states.
// Nothing physical differs between the two runs; only the heap addresses of the geoms do (other
// allocations are made in between), so any difference comes from an iteration order that
// depends on pointer values (ODE moves a geom whose pose is set to the front of its space's
// list, so the order of dGeomSetPosition calls is the order in which pairs are collided and
// contacts are numbered).
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <vector>

#include "reference_fixture.hpp"

namespace rheofeed::reference::test {
namespace {

constexpr int kBoxes = 40;
constexpr int kSteps = 200;
constexpr double kStep = 1e-3;  // s

// A 40-box pile: 4 x 2 columns of 5 boxes, slightly offset and rotated so that they topple
// onto each other, dropped on the ground.
std::vector<BodyState> runPile() {
  World world(defaultSettings());
  addGround(world);
  std::vector<BodyId> ids;
  for (int k = 0; k < kBoxes; ++k) {
    const int column = k % 8, level = k / 8;
    BodyState s =
        restingAt({0.07 * (column % 4) + 0.01 * level, 0.07 * (column / 4), 0.03 + 0.055 * level},
                  quaternionAboutY(0.05 * (k % 5)));
    ids.push_back(addBox(world, 0.1, {0.05, 0.05, 0.05}, s).id);
  }
  for (int i = 0; i < kSteps; ++i) world.step(kStep);
  std::vector<BodyState> out;
  for (BodyId id : ids) out.push_back(world.state(id));
  return out;
}

bool bitIdentical(const BodyState& a, const BodyState& b) {
  const double va[] = {a.position.x,        a.position.y,         a.position.z,
                       a.orientation.w,     a.orientation.x,      a.orientation.y,
                       a.orientation.z,     a.linear_velocity.x,  a.linear_velocity.y,
                       a.linear_velocity.z, a.angular_velocity.x, a.angular_velocity.y,
                       a.angular_velocity.z};
  const double vb[] = {b.position.x,        b.position.y,         b.position.z,
                       b.orientation.w,     b.orientation.x,      b.orientation.y,
                       b.orientation.z,     b.linear_velocity.x,  b.linear_velocity.y,
                       b.linear_velocity.z, b.angular_velocity.x, b.angular_velocity.y,
                       b.angular_velocity.z};
  return std::memcmp(va, vb, sizeof va) == 0;
}

TEST(ReferenceDeterminism, SamePileTwiceGivesBitIdenticalStates) {
  initOdeOnce();
  const std::vector<BodyState> first = runPile();
  // Different heap layout for the second world: keep blocks of assorted sizes alive.
  std::vector<std::unique_ptr<char[]>> clutter;
  for (int k = 1; k <= 300; ++k) clutter.emplace_back(new char[static_cast<std::size_t>(k * 37)]);
  const std::vector<BodyState> second = runPile();
  ASSERT_EQ(first.size(), second.size());
  int differing = 0;
  for (std::size_t k = 0; k < first.size(); ++k)
    differing += bitIdentical(first[k], second[k]) ? 0 : 1;
  EXPECT_EQ(differing, 0) << differing << " of " << first.size() << " boxes differ";
  // The pile did move (the test would be empty otherwise): the top boxes fell.
  EXPECT_LT(first.back().position.z, 0.03 + 0.055 * 4 - 0.01);
}

}  // namespace
}  // namespace rheofeed::reference::test
