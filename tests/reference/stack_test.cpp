// SPDX-License-Identifier: MIT
// A stack of boxes at rest on the ground: the contact impulses carry the weight above them.
//
// Oracle: a body at rest keeps zero momentum, so over one step the net impulse on body k is
// m_k (v_k+ - v_k) + m_k g h = m_k g h. Summing from the top down, the normal impulses across the
// interface under body k add up to h g (m_k + ... + m_top), and the ground carries h g times the
// total mass. The individual impulses are not unique (four or more contacts per face on three
// constrained directions: N is rank deficient), but these sums are.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "reference_fixture.hpp"

namespace rheofeed::reference::test {
namespace {

constexpr double kStep = 1e-3;       // s
constexpr double kSettleTime = 1.0;  // s
constexpr double kHeight = 0.1;      // height of every box (m)
// Boxes start this far into each other (and the ground), so that every interface has contacts on
// the first step (placed "exactly" touching, rounding could leave a gap of 1e-17 m).
constexpr double kInitialPenetration = 1e-9;  // m

struct Layer {
  double mass;   // kg
  double width;  // side of the square footprint (m)
};
// Bottom to top. Masses are not monotonic so that a sum of the wrong layers cannot pass.
const std::vector<Layer> kLayers = {{1.0, 0.4}, {3.0, 0.3}, {0.5, 0.2}, {2.0, 0.1}};

// Settled: every velocity below this (m/s); then a step changes momenta by far less than the
// relative kImpulseTolerance of m g h (g h = 1e-2 m/s).
constexpr double kSettledSpeed = 1e-7;
// Per-interface sums relative to h g m_above: a settled body's momentum changes by at most
// 2 kSettledSpeed per step, against g h (the solver's 1e-8 residual is smaller still).
constexpr double kImpulseTolerance = 2 * kSettledSpeed / (kGravity * kStep);

TEST(ReferenceStack, NormalImpulsesCarryTheWeightAboveOnceSettled) {
  initOdeOnce();
  World world(defaultSettings());
  addGround(world);
  std::vector<BodyId> ids;
  double z = -kInitialPenetration;
  for (const Layer& layer : kLayers) {
    const double centre = z + kHeight / 2;
    ids.push_back(
        addBox(world, layer.mass, {layer.width, layer.width, kHeight}, restingAt({0, 0, centre}))
            .id);
    z = centre + kHeight / 2 - kInitialPenetration;
  }
  StepReport report;
  const int steps = static_cast<int>(std::lround(kSettleTime / kStep));
  for (int k = 0; k < steps; ++k) report = world.step(kStep);
  std::printf("stack: last step %d contacts, solver %s, %d iterations, residual %.2e\n",
              report.contacts, ccp::toString(report.solve.status), report.solve.iterations,
              report.solve.residual);
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const BodyState& s = world.state(ids[k]);
    EXPECT_LE(norm(s.linear_velocity), kSettledSpeed) << "layer " << k << " not settled";
    EXPECT_LE(norm(s.angular_velocity) * kLayers[k].width, kSettledSpeed)
        << "layer " << k << " not settled";
  }

  // Upward impulse across the interface under each layer (index 0: the ground).
  const std::size_t n = ids.size();
  std::vector<double> carried(n, 0.0);
  std::vector<int> contacts(n, 0);
  for (const ContactImpulse& c : world.contacts()) {
    // The upper body of the pair and the vertical impulse it receives: gamma_n acts on body1
    // along +normal (normal from g2 into g1), so on body2 along -normal.
    const BodyId upper = std::max(c.body1, c.body2);
    const BodyId lower = std::min(c.body1, c.body2);  // kStatic (-1) for the ground
    const double on_upper = c.normal_impulse * c.normal.z * (upper == c.body1 ? 1.0 : -1.0);
    ASSERT_EQ(upper, lower + 1) << "contact between non-adjacent layers";
    carried[static_cast<std::size_t>(upper)] += on_upper;
    ++contacts[static_cast<std::size_t>(upper)];
  }
  double mass_above = 0;
  for (std::size_t k = n; k-- > 0;) {
    mass_above += kLayers[k].mass;
    const double expected = kStep * kGravity * mass_above;
    std::printf(
        "interface under layer %zu (%d contacts): sum gamma_n = %.9f N s vs h g m_above "
        "= %.9f N s (rel. error %.1e)\n",
        k, contacts[k], carried[k], expected, carried[k] / expected - 1);
    EXPECT_GE(contacts[k], 3) << "layer " << k << " must rest on a face";
    EXPECT_NEAR(carried[k] / expected, 1.0, kImpulseTolerance) << "interface under layer " << k;
  }
}

}  // namespace
}  // namespace rheofeed::reference::test
