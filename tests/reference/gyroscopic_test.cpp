// SPDX-License-Identifier: MIT
// A free rigid body (no gravity, no contact, no torque) conserves its kinetic energy
// E = 1/2 w^T I_world w and the magnitude of its angular momentum L = I_world w (Euler's
// equations; both are first integrals). A box with distinct principal moments spun near its
// intermediate axis tumbles (the axis is unstable, Dzhanibekov effect), which is where an
// explicit gyroscopic term pumps energy; spun near its largest axis it stays near that spin.
//
// Oracle: conservation, from outside the code. The integrator may dissipate (implicit schemes
// do) but must never add energy, beyond round-off.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "reference_fixture.hpp"

namespace rheofeed::reference::test {
namespace {

constexpr double kMass = 1.0;         // kg
constexpr Vec3 kSize{0.3, 0.2, 0.1};  // m: I_x < I_y < I_z, see the tumbling test
constexpr int kSteps = 2000;          // >= 1000 steps at each h
// Energy may not grow beyond accumulated round-off: a few ulps per step over kSteps steps.
constexpr double kEnergyGrowth = 1e-12;  // relative
// |L| of the implicit midpoint rule is conserved exactly in exact arithmetic (its body-frame
// update is a Cayley rotation of L); what remains is round-off of the quaternion and the
// Newton solve, ~1e-16 per step, and the energy guard's rescaling at round-off level.
constexpr double kMomentumDrift = 1e-10;  // relative
// Spin about the largest principal axis (stable): energy kept to the same round-off level.
constexpr double kStableEnergyDrift = 1e-10;  // relative

struct Invariants {
  double energy, momentum;
  double body_wy;  // angular velocity along the body's y axis (rad/s)
};

// E and |L| computed from the state with this test's own rotation of the body-frame inertia.
Invariants invariants(const BodyState& s, const std::array<double, 9>& inertia_body) {
  const Eigen::Quaterniond q(s.orientation.w, s.orientation.x, s.orientation.y, s.orientation.z);
  const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
  Eigen::Matrix3d i_body;
  for (int k = 0; k < 9; ++k) i_body(k / 3, k % 3) = inertia_body[static_cast<std::size_t>(k)];
  const Eigen::Vector3d w(s.angular_velocity.x, s.angular_velocity.y, s.angular_velocity.z);
  const Eigen::Vector3d l = r * i_body * r.transpose() * w;
  return {0.5 * w.dot(l), l.norm(), (r.transpose() * w).y()};
}

struct Drift {
  double max_energy_ratio = 0;  // max E / E0
  double min_energy_ratio = 1e300;
  double max_momentum_drift = 0;  // max ||L| / |L0| - 1|
  double min_body_wy = 1e300;     // min angular velocity along the body's y axis (rad/s)
};

Drift spin(const Vec3& w0, double h) {
  Settings settings = defaultSettings();
  settings.gravity = {0, 0, 0};
  World world(settings);
  const auto inertia = boxInertia(kMass, kSize.x, kSize.y, kSize.z);
  BodyState s0;
  s0.angular_velocity = w0;
  const BoxBody box = addBox(world, kMass, kSize, s0);
  const Invariants start = invariants(world.state(box.id), inertia);
  Drift d;
  for (int k = 0; k < kSteps; ++k) {
    world.step(h);
    const Invariants now = invariants(world.state(box.id), inertia);
    d.max_energy_ratio = std::max(d.max_energy_ratio, now.energy / start.energy);
    d.min_energy_ratio = std::min(d.min_energy_ratio, now.energy / start.energy);
    d.max_momentum_drift =
        std::max(d.max_momentum_drift, std::abs(now.momentum / start.momentum - 1));
    d.min_body_wy = std::min(d.min_body_wy, now.body_wy);
  }
  return d;
}

TEST(ReferenceGyroscopic, TumblingBoxNeverGainsEnergyAndKeepsAngularMomentum) {
  initOdeOnce();
  // Principal moments (body axes): I_x = m (0.2^2 + 0.1^2) / 12 (smallest), I_y = m (0.3^2 +
  // 0.1^2) / 12 (intermediate), I_z = m (0.3^2 + 0.2^2) / 12 (largest). Spin about y, perturbed.
  const Vec3 w0{0.01, 10.0, 0.01};  // rad/s
  for (double h : {0.05, 0.01}) {
    const Drift d = spin(w0, h);
    std::printf(
        "tumbling, h = %.2f s, %d steps: E/E0 in [%.15f, %.15f], max ||L|/|L0| - 1| = %.2e, "
        "min body w_y = %.3f rad/s\n",
        h, kSteps, d.min_energy_ratio, d.max_energy_ratio, d.max_momentum_drift, d.min_body_wy);
    EXPECT_LE(d.max_energy_ratio, 1 + kEnergyGrowth) << "h = " << h;
    EXPECT_LE(d.max_momentum_drift, kMomentumDrift) << "h = " << h;
    // It does tumble: the spin about y reverses in the body frame (growth rate
    // w sqrt((I_y - I_x)(I_z - I_y) / (I_x I_z)) = 4.8 1/s, so the 1e-3 perturbation has grown to
    // a flip within ~1.5 s of the 20-100 s run). An energy-conserving flip reverses w_y fully.
    EXPECT_LT(d.min_body_wy, -0.5 * w0.y) << "h = " << h;
  }
}

TEST(ReferenceGyroscopic, SpinAboutLargestAxisKeepsItsEnergy) {
  initOdeOnce();
  const Vec3 w0{0.01, 0.01, 10.0};  // rad/s, about z (largest moment), perturbed
  for (double h : {0.05, 0.01}) {
    const Drift d = spin(w0, h);
    std::printf("stable spin, h = %.2f s: E/E0 in [%.15f, %.15f], max ||L|/|L0| - 1| = %.2e\n", h,
                d.min_energy_ratio, d.max_energy_ratio, d.max_momentum_drift);
    EXPECT_LE(d.max_energy_ratio, 1 + kEnergyGrowth) << "h = " << h;
    EXPECT_GE(d.min_energy_ratio, 1 - kStableEnergyDrift) << "h = " << h;
    EXPECT_LE(d.max_momentum_drift, kMomentumDrift) << "h = " << h;
  }
}

}  // namespace
}  // namespace rheofeed::reference::test
