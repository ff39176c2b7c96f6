// SPDX-License-Identifier: MIT
// A block on an incline (a static tilted box, gravity -z): it sticks iff tan(theta) <= mu, and
// when it slides it accelerates down the slope at a = g (sin(theta) - mu cos(theta)).
//
// Oracles (per unit mass, s along the slope downhill, n along its outward normal):
// - sticking needs a friction force g sin(theta) <= mu g cos(theta), i.e. tan(theta) <= mu;
// - sliding: linear momentum along (s, n) with every contact sliding downhill gives
//       v_s(t) + mu v_n(t) = a t,    a = g (sin(theta) - mu cos(theta))
//   (the sum of normal impulses cancels, as in sliding_test.cpp), so after K steps of h the
//   displacement obeys  s + mu n = a h^2 K (K + 1) / 2 = a T (T + h) / 2  (semi-implicit Euler).
//   True Coulomb keeps n = 0; the relaxed problem lets the block hop (see sliding_test.cpp), so
//   n > 0 and s falls short of the Coulomb slide by mu n.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>

#include "reference_fixture.hpp"

namespace rheofeed::reference::test {
namespace {

constexpr double kMu = 0.5;                    // friction coefficient
constexpr double kMargin = 2.0 * kPi / 180.0;  // angle either side of atan(mu) (rad)
constexpr double kStep = 1e-3;                 // s
constexpr double kDuration = 1.0;              // s
constexpr double kMass = 1.0;                  // kg
constexpr double kSide = 0.1;                  // block side (m)
constexpr double kSlopeThickness = 0.2;        // m
// The block starts this far into the slope: placed "exactly" on it, rounding can leave it 1e-17 m
// above, so it would fall freely for one step and land g h^2 deep, and ERP's push-out of that
// penetration would inflate the landing's normal impulse enough to make it stick for a step.
constexpr double kInitialPenetration = 1e-9;  // m

struct Measured {
  double along = 0;   // displacement along the slope, downhill (m)
  double normal = 0;  // displacement along the slope's normal (m)
};

/// Runs a block placed at rest on a slope tilted by `theta` (rad) for kDuration.
Measured runIncline(double theta, const Settings& settings) {
  World world(settings);
  const auto rotation = rotationAboutY(theta);
  addStaticBox(world, {3.0, 1.0, kSlopeThickness}, {0, 0, 0}, rotation);
  const Vec3 downhill{std::cos(theta), 0, -std::sin(theta)};  // R x
  const Vec3 normal{std::sin(theta), 0, std::cos(theta)};     // R z
  const Vec3 start = (kSlopeThickness / 2 + kSide / 2 - kInitialPenetration) * normal;
  const BoxBody block =
      addBox(world, kMass, {kSide, kSide, kSide}, restingAt(start, quaternionAboutY(theta)));
  const int steps = static_cast<int>(std::lround(kDuration / kStep));
  for (int k = 0; k < steps; ++k) world.step(kStep);
  const Vec3 d = world.state(block.id).position - start;
  return {dot(d, downhill), dot(d, normal)};
}

Settings inclineSettings(int coulomb_outer_iterations) {
  Settings s =
      coulomb_outer_iterations > 0 ? coulombSettings(coulomb_outer_iterations) : defaultSettings();
  s.default_mu = kMu;
  return s;
}

TEST(ReferenceIncline, BlockSticksIffTanThetaAtMostMu) {
  initOdeOnce();
  const double theta_critical = std::atan(kMu);
  const double below = theta_critical - kMargin, above = theta_critical + kMargin;
  for (int outer : {0, 50}) {
    SCOPED_TRACE(outer > 0 ? "true Coulomb" : "relaxed CCP");
    const Settings settings = inclineSettings(outer);
    // Sticking, ODE's CFM makes the contacts compliant: they creep at (cfm / h) gamma_t, at most
    // cfm m g sin(theta) in all, so over kDuration the block creeps at most this far.
    const double creep_bound = settings.cfm * kMass * kGravity * std::sin(below) * kDuration;
    const Measured stuck = runIncline(below, settings);
    // Sliding just above, it should cover a T^2 / 2 less what hopping loses (see the oracle).
    const double a = kGravity * (std::sin(above) - kMu * std::cos(above));
    const double expected = 0.5 * a * kDuration * kDuration;
    const Measured slid = runIncline(above, settings);
    std::printf(
        "%s: theta = atan(mu) - 2 deg: %.3e m along the slope (creep bound %.3e m); "
        "atan(mu) + 2 deg: %.5f m vs a T^2/2 = %.5f m\n",
        outer > 0 ? "Coulomb" : "relaxed", stuck.along, creep_bound, slid.along, expected);
    EXPECT_LE(std::abs(stuck.along), creep_bound);
    EXPECT_GT(slid.along, 0.5 * expected) << "clearly sliding";
  }
}

TEST(ReferenceIncline, SlidingBlockAcceleratesAtGSinMinusMuCos) {
  initOdeOnce();
  const double theta = std::atan(kMu) + kMargin;
  const double a = kGravity * (std::sin(theta) - kMu * std::cos(theta));
  const double identity = 0.5 * a * kDuration * (kDuration + kStep);  // s + mu n, see the oracle
  // The identity holds to the accumulated solver residual (1e-8 per step, 1000 steps, times T)
  // as long as every contact slides at every step.
  constexpr double kIdentityTolerance = 1e-5;  // m
  // True Coulomb keeps the block on the surface: n within the CFM resting penetration.
  constexpr double kCoulombNormalTolerance = 1e-6;  // m
  const Measured coulomb = runIncline(theta, inclineSettings(50));
  const Measured relaxed = runIncline(theta, inclineSettings(0));
  for (const auto& [name, m] : {std::pair{"Coulomb", coulomb}, std::pair{"relaxed", relaxed}}) {
    std::printf("%s: s = %.6f m, n = %.2e m, s + mu n = %.9f m vs a T (T + h) / 2 = %.9f m\n", name,
                m.along, m.normal, m.along + kMu * m.normal, identity);
    EXPECT_NEAR(m.along + kMu * m.normal, identity, kIdentityTolerance) << name;
  }
  EXPECT_NEAR(coulomb.normal, 0.0, kCoulombNormalTolerance);
  // The relaxed block hops (launched at mu |u_t| at each landing): it ends above the surface
  // and, by the identity, short of the Coulomb slide by mu n.
  EXPECT_GT(relaxed.normal, kCoulombNormalTolerance);
  EXPECT_LT(relaxed.along, coulomb.along);
}

}  // namespace
}  // namespace rheofeed::reference::test
