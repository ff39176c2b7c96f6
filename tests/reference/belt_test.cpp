// SPDX-License-Identifier: MIT
// A box dropped at rest on a belt: the ground plane is a stationary geom with the rheonomic law
// MotionLaw::belt(+x, V), so its contacts carry c_t = V x (NOTES section 1). Friction drags the
// box at mu g until it reaches V, after V / (mu g), and then the contact sticks: the box moves at
// exactly V with zero slip and zero friction.
//
// Oracle, as for the sliding block (sliding_test.cpp) with the friction now pointing +x: while
// every contact slips, linear momentum gives v_x(t) - mu v_z(t) = mu g t, so true Coulomb
// (v_z = 0) reaches V at t = V / (mu g) on the step grid. Once stuck, the box needs no friction:
// u_t = v_x - V = 0 is a solution with gamma_t = 0, and CFM's compliance (which creeps only under
// a tangential load) changes nothing, so v_x = V to the solver's tolerance once a short transient
// is over: while slipping, the friction torque loads the trailing corners more and ODE's CFM lets
// them sink more (the box tilts by ~1e-6 rad); once stuck, ERP pushes that tilt out, by a factor
// (1 - erp) per step, which moves the centre of mass at ~1e-5 m/s for a few steps.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "reference_fixture.hpp"

namespace rheofeed::reference::test {
namespace {

constexpr double kMu = 0.4;         // friction coefficient
constexpr double kBeltSpeed = 0.5;  // V (m/s) along +x
constexpr double kStep = 1e-3;      // s
constexpr double kDuration = 0.5;   // s, about 4 V / (mu g)
constexpr double kSide = 0.1;       // m
constexpr double kMass = 1.0;       // kg

// Stuck: velocity error of a converged solve, 1e-8 relative residual times (1 + ||r||) ~ 1 m/s,
// with margin for its accumulation over the run.
constexpr double kStickVelocityTolerance = 1e-6;  // m/s
// "Reached V": within the CFM-tilt transient above (~1e-5 m/s), far below mu g h = 4e-3 m/s.
constexpr double kReachTolerance = 1e-4;  // m/s
// The tilt transient decays as (1 - erp)^k = 0.8^k: 50 steps divide it by 7e4.
constexpr int kSettlingSteps = 50;

struct BeltRun {
  double t_reach = -1;        // first time |v_x - V| <= kReachTolerance (s)
  double worst_after = 0;     // max |v - V x| from kSettlingSteps after t_reach (m/s)
  double worst_slip = 0;      // max contact slip, same period (m/s)
  double worst_friction = 0;  // max |friction impulse| of a contact, same period (N s)
  double worst_identity = 0;  // max |v_x - mu v_z - mu g t| before t_reach (m/s)
};

BeltRun runBelt(int coulomb_outer_iterations) {
  Settings settings =
      coulomb_outer_iterations > 0 ? coulombSettings(coulomb_outer_iterations) : defaultSettings();
  settings.default_mu = kMu;
  World world(settings);
  const dGeomID belt = addGround(world);
  world.setFeeder(belt, MotionLaw::belt({1, 0, 0}, kBeltSpeed));
  const BoxBody box = addBox(world, kMass, {kSide, kSide, kSide}, restingAt({0, 0, kSide / 2}));
  BeltRun run;
  int steps_since_reach = 0;
  while (world.time() < kDuration) {
    world.step(kStep);
    const BodyState& s = world.state(box.id);
    const Vec3 error = s.linear_velocity - Vec3{kBeltSpeed, 0, 0};
    if (run.t_reach < 0) {
      if (std::abs(error.x) <= kReachTolerance) {
        run.t_reach = world.time();
      } else {
        run.worst_identity =
            std::max(run.worst_identity, std::abs(s.linear_velocity.x - kMu * s.linear_velocity.z -
                                                  kMu * kGravity * world.time()));
      }
      continue;
    }
    if (++steps_since_reach < kSettlingSteps) continue;
    run.worst_after = std::max(run.worst_after, norm(error));
    for (const ContactImpulse& c : world.contacts()) {
      run.worst_slip = std::max(run.worst_slip, norm(c.slip));
      run.worst_friction = std::max(run.worst_friction, norm(c.tangential_impulse));
    }
  }
  return run;
}

TEST(ReferenceBelt, CoulombBoxReachesBeltSpeedAfterVOverMuGThenSticksExactly) {
  initOdeOnce();
  // Momentum identity while slipping: accumulated solver residual over ~130 steps.
  constexpr double kIdentityTolerance = 1e-6;  // m/s
  const BeltRun run = runBelt(50);
  const double t_expected = kBeltSpeed / (kMu * kGravity);
  std::printf(
      "Coulomb belt: reached V at %.4f s vs V/(mu g) = %.4f s; afterwards |v - V| <= %.2e "
      "m/s, slip <= %.2e m/s, friction <= %.2e N s; identity error %.2e m/s\n",
      run.t_reach, t_expected, run.worst_after, run.worst_slip, run.worst_friction,
      run.worst_identity);
  ASSERT_GT(run.t_reach, 0) << "never reached belt speed";
  // On the step grid: V is reached at the first step with mu g t >= V.
  EXPECT_NEAR(run.t_reach, t_expected, kStep);
  EXPECT_LE(run.worst_identity, kIdentityTolerance);
  EXPECT_LE(run.worst_after, kStickVelocityTolerance);
  EXPECT_LE(run.worst_slip, kStickVelocityTolerance);
}

TEST(ReferenceBelt, RelaxedBoxReachesBeltSpeedNearVOverMuGThenSticksExactly) {
  initOdeOnce();
  const BeltRun run = runBelt(0);
  const double t_expected = kBeltSpeed / (kMu * kGravity);
  // The relaxed box hops while it slips (launched at mu |u_t| <= mu V): friction acts only at
  // landings, so V is reached at a landing, up to one hop 2 mu V / g after V / (mu g).
  const double hop = 2 * kMu * kBeltSpeed / kGravity;
  std::printf(
      "relaxed belt: reached V at %.4f s vs V/(mu g) = %.4f s (one hop %.4f s); "
      "afterwards |v - V| <= %.2e m/s, slip <= %.2e m/s, friction <= %.2e N s; identity "
      "error while slipping %.2e m/s\n",
      run.t_reach, t_expected, hop, run.worst_after, run.worst_slip, run.worst_friction,
      run.worst_identity);
  ASSERT_GT(run.t_reach, 0) << "never reached belt speed";
  EXPECT_GE(run.t_reach, t_expected - kStep);
  EXPECT_LE(run.t_reach, t_expected + hop);
  EXPECT_LE(run.worst_after, kStickVelocityTolerance);
  EXPECT_LE(run.worst_slip, kStickVelocityTolerance);
}

}  // namespace
}  // namespace rheofeed::reference::test
