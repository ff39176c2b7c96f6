// SPDX-License-Identifier: MIT
// A sphere launched without spin on a flat plane slides, friction spins it up, and it ends
// rolling at 5/7 of its initial speed, with w r = v.
//
// Oracle: every contact impulse acts at the contact point p = centre - r z (ODE's sphere-plane
// contact), and gravity acts along the vertical through the centre, so the angular momentum about
// the ground point under the centre is conserved, in continuous time and exactly in the
// semi-implicit step (the impulse gamma_x changes m v_x by gamma_x and I w_y by -r gamma_x):
//     L = m v_x r + I w_y = m v0 r,   I = 2/5 m r^2.
// Rolling (no slip: v_x = w_y r) then gives v = m v0 r^2 / (m r^2 + I) = 5/7 v0, for true Coulomb
// and for the relaxed problem alike (the relaxed sphere hops while it slips, which changes when
// it starts rolling but not at what speed). With true Coulomb the slip decays at a constant rate:
//     d(v - w r)/dt = -mu g - mu g r^2 m / I = -7/2 mu g   =>  rolling after t = 2 v0 / (7 mu g).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "reference_fixture.hpp"

namespace rheofeed::reference::test {
namespace {

constexpr double kMu = 0.2;        // friction coefficient
constexpr double kV0 = 2.0;        // initial speed along +x, no spin (m/s)
constexpr double kRadius = 0.05;   // m
constexpr double kMass = 1.0;      // kg
constexpr double kStep = 1e-3;     // s
constexpr double kDuration = 1.0;  // s, more than three times the Coulomb rolling time

// Velocity-level identities of converged solves: 1e-8 relative residual per step, ~1000 steps.
constexpr double kVelocityTolerance = 1e-6;  // m/s
// Rolling starts when the slip falls below this (m/s): far below the per-step slip decrease
// 7/2 mu g h = 7e-3 m/s, far above the solver's resolution.
constexpr double kRollingSlip = 1e-5;

struct RollingRun {
  double t_rolling = -1;      // first time |v_x - w_y r| <= kRollingSlip (s)
  double final_v = 0;         // v_x at the end (m/s)
  double final_slip = 0;      // v_x - w_y r at the end (m/s)
  double worst_momentum = 0;  // max |L / (m r) - v0| over the run (m/s)
  double max_height = 0;      // max centre height above r (m)
};

RollingRun runSphere(int coulomb_outer_iterations) {
  Settings settings =
      coulomb_outer_iterations > 0 ? coulombSettings(coulomb_outer_iterations) : defaultSettings();
  settings.default_mu = kMu;
  World world(settings);
  addGround(world);
  BodyState start = restingAt({0, 0, kRadius});
  start.linear_velocity = {kV0, 0, 0};
  const BodyId sphere = addSphere(world, kMass, kRadius, start);
  const double inertia = 0.4 * kMass * kRadius * kRadius;
  RollingRun run;
  while (world.time() < kDuration) {
    world.step(kStep);
    const BodyState& s = world.state(sphere);
    const double slip = s.linear_velocity.x - s.angular_velocity.y * kRadius;
    const double l = kMass * s.linear_velocity.x * kRadius + inertia * s.angular_velocity.y;
    run.worst_momentum = std::max(run.worst_momentum, std::abs(l / (kMass * kRadius) - kV0));
    run.max_height = std::max(run.max_height, s.position.z - kRadius);
    if (run.t_rolling < 0 && std::abs(slip) <= kRollingSlip) run.t_rolling = world.time();
    run.final_v = s.linear_velocity.x;
    run.final_slip = slip;
  }
  return run;
}

void expectRollsAtFiveSevenths(const RollingRun& run, const char* mode) {
  std::printf(
      "%s sphere: final v / v0 = %.9f (5/7 = %.9f), final v - w r = %.2e m/s, rolling "
      "from %.4f s, worst |L/(m r) - v0| = %.2e m/s, max hop %.2e m\n",
      mode, run.final_v / kV0, 5.0 / 7.0, run.final_slip, run.t_rolling, run.worst_momentum,
      run.max_height);
  EXPECT_LE(run.worst_momentum, kVelocityTolerance);
  EXPECT_NEAR(run.final_v, 5.0 / 7.0 * kV0, kVelocityTolerance);
  EXPECT_NEAR(run.final_slip, 0.0, kVelocityTolerance);
  ASSERT_GT(run.t_rolling, 0) << "never rolled";
}

TEST(ReferenceRolling, CoulombSphereEndsRollingAtFiveSeventhsAfterTwoV0OverSevenMuG) {
  initOdeOnce();
  const RollingRun run = runSphere(50);
  expectRollsAtFiveSevenths(run, "Coulomb");
  // Slip decreases by 7/2 mu g h per step: rolling on the first step at or after 2 v0/(7 mu g).
  EXPECT_NEAR(run.t_rolling, 2 * kV0 / (7 * kMu * kGravity), kStep);
  // True Coulomb never lifts the sphere (CFM sinks it by ~cfm m g, 1e-7 m at most).
  EXPECT_LE(run.max_height, 1e-7);
}

TEST(ReferenceRolling, RelaxedSphereEndsRollingAtFiveSevenths) {
  initOdeOnce();
  const RollingRun run = runSphere(0);
  expectRollsAtFiveSevenths(run, "relaxed");
  // It hops while slipping (launched at mu |u_t| <= mu v0: apex up to (mu v0)^2 / 2g = 8 mm),
  // friction acts only at landings, so rolling may start up to one hop 2 mu v0 / g later.
  EXPECT_GT(run.max_height, 1e-4) << "the relaxed sphere is expected to hop";
  EXPECT_GE(run.t_rolling, 2 * kV0 / (7 * kMu * kGravity) - kStep);
  EXPECT_LE(run.t_rolling, 2 * kV0 / (7 * kMu * kGravity) + 2 * kMu * kV0 / kGravity);
}

}  // namespace
}  // namespace rheofeed::reference::test
