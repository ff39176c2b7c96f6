// SPDX-License-Identifier: MIT
// Global Newton steps of NSGS (plugin/src/ccp/global_newton.cpp): a box's four coplanar corner
// contacts with a compliance (the reference world's cfm / h), whose impulses Gauss-Seidel
// redistributes only at the compliance's pace, against the compliant static solution derived
// here from the rigid body's equations and against a sliding box's exact motion; and the Siconos
// box stack (tests/data/fc3d) to 1e-8.
#include "rheofeed/ccp/fc3d_reader.hpp"
#include "rheofeed/ccp/nsgs.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <string>
#include <vector>

#include "test_support.hpp"

#ifndef RHEOFEED_FC3D_DIR
#error "RHEOFEED_FC3D_DIR must be defined to the fc3d data directory"
#endif

namespace rheofeed::ccp {
namespace {

constexpr double kGravity = 9.81;  // m/s^2
// The box: 20 g, half sizes 10 x 6 mm in the plane, centre of mass 4 mm above it, mu 0.4, a step
// of 10 ms, and the main demo's compliance cfm / h = 1e-5 / 0.01 (1/kg): four orders of
// magnitude under the corners' 1/m, so the corner block of N is rank deficient up to it.
constexpr double kMass = 0.02, kHalfX = 0.010, kHalfY = 0.006, kHeight = 0.004;
constexpr double kMu = 0.4, kStep = 0.01, kCompliance = 1e-3;
// Coulomb tolerance of the solves (the solver's scale-invariant residual).
constexpr double kTolerance = 1e-12;
// Impulse error allowed against the closed form, relative to the impulses: the residual bounds
// the velocity error by kTolerance |r| (~1e-13 m/s), which moves impulses by at most that over the
// compliance (~1e-10 N s against ~5e-4 N s).
constexpr double kImpulseAgreement = 1e-6;
// Sweep budget of the box solves: sweeps alone move the corners' split by about compliance
// over 1/m (1e-4) of its error per sweep.
constexpr int kBoxSweeps = 2000;

struct Box {
  Eigen::MatrixXd d;       // 6 x 12 (generalised impulse of each contact direction)
  Eigen::MatrixXd minv;    // 6 x 6
  Eigen::VectorXd v_free;  // 6, the velocity after a step without contact (m/s, rad/s)
  Problem dense, matrix_free;
};

// Completes `box` from its contact directions box.d (6 nb x 3 nc), the bodies' diagonal inverse
// masses and free velocities: the dense problem with the compliance kCompliance on N's diagonal,
// and the matrix-free one as the reference world builds it, N + c I = [D; sqrt(c) I]^T
// blkdiag(M^-1, I) [D; sqrt(c) I]. Every contact has mu = kMu.
void finish(Box& box, const Eigen::VectorXd& inverse_mass, const Eigen::VectorXd& v_free) {
  const Eigen::Index dofs = box.d.rows(), n = box.d.cols();
  box.minv = inverse_mass.asDiagonal();
  box.v_free = v_free;
  const Eigen::VectorXd r = box.d.transpose() * v_free;
  const Eigen::VectorXd mu = Eigen::VectorXd::Constant(n / 3, kMu);
  Eigen::MatrixXd delassus = box.d.transpose() * box.minv * box.d;
  delassus.diagonal().array() += kCompliance;
  box.dense = Problem::makeDense(delassus, r, mu);
  std::vector<Eigen::Triplet<double>> d_entries, m_entries;
  for (Eigen::Index row = 0; row < dofs; ++row) {
    for (Eigen::Index col = 0; col < n; ++col) {
      if (box.d(row, col) != 0.0) d_entries.emplace_back(row, col, box.d(row, col));
    }
    m_entries.emplace_back(row, row, inverse_mass[row]);
  }
  for (Eigen::Index k = 0; k < n; ++k) {
    d_entries.emplace_back(dofs + k, k, std::sqrt(kCompliance));
    m_entries.emplace_back(dofs + k, dofs + k, 1.0);
  }
  SparseMatrix d_aug(dofs + n, n), minv_aug(dofs + n, dofs + n);
  d_aug.setFromTriplets(d_entries.begin(), d_entries.end());
  minv_aug.setFromTriplets(m_entries.begin(), m_entries.end());
  box.matrix_free = Problem::makeMatrixFree(d_aug, minv_aug, r, mu);
}

// A box resting on a plane inclined by theta, frame x down the slope, y across, z out of the
// plane (each contact's n = z, t1 = x, t2 = y); at rest at the start of the step.
Box boxOnIncline(double theta) {
  Box box;
  box.d = Eigen::MatrixXd::Zero(6, 12);
  int i = 0;
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) {
      const Eigen::Vector3d p(sx * kHalfX, sy * kHalfY, -kHeight);  // corner from the centre
      const Eigen::Vector3d axes[3] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(),
                                       Eigen::Vector3d::UnitY()};
      for (int k = 0; k < 3; ++k) {
        box.d.block<3, 1>(0, 3 * i + k) = axes[k];
        box.d.block<3, 1>(3, 3 * i + k) = p.cross(axes[k]);
      }
      ++i;
    }
  }
  const double hz = kHeight;  // the box is 2 kHeight tall, centred
  Eigen::VectorXd inverse_mass(6);
  inverse_mass << 1 / kMass, 1 / kMass, 1 / kMass, 3 / (kMass * (kHalfY * kHalfY + hz * hz)),
      3 / (kMass * (kHalfX * kHalfX + hz * hz)), 3 / (kMass * (kHalfX * kHalfX + kHalfY * kHalfY));
  Eigen::VectorXd v_free = Eigen::VectorXd::Zero(6);
  v_free.head<3>() = kStep * kGravity * Eigen::Vector3d(std::sin(theta), 0, -std::cos(theta));
  finish(box, inverse_mass, v_free);
  return box;
}

// Fills the 6 x 3 block of d for contact `contact` acting on a body at the lever arm `arm` (from
// the body's centre, m) along the contact frame (n = z, t1 = x, t2 = y), with sign `sign`.
void addContact(Eigen::MatrixXd& d, int body, int contact, const Eigen::Vector3d& arm,
                double sign) {
  const Eigen::Vector3d axes[3] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(),
                                   Eigen::Vector3d::UnitY()};
  for (int k = 0; k < 3; ++k) {
    d.block<3, 1>(6 * body, 3 * contact + k) += sign * axes[k];
    d.block<3, 1>(6 * body + 3, 3 * contact + k) += sign * arm.cross(axes[k]);
  }
}

// A second box, half the mass, 0.6 times as long and wide, resting on the first box of
// boxOnIncline 2 mm off centre down the slope: 8 corner contacts, 4 of them between the two
// bodies (each pushes the upper box along its normal and the lower one back), so N couples the
// bodies, and the upper box's offset loads the lower box's corners unevenly.
Box stackOnIncline(double theta) {
  constexpr double kTopMass = 0.5 * kMass, kTopScale = 0.6, kOffset = 0.002;
  const double hx = kTopScale * kHalfX, hy = kTopScale * kHalfY, hz = kHeight;
  Box box;
  box.d = Eigen::MatrixXd::Zero(12, 24);
  int i = 0;
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) {
      addContact(box.d, 0, i, {sx * kHalfX, sy * kHalfY, -kHeight}, 1.0);  // on the plane
      addContact(box.d, 1, 4 + i, {sx * hx, sy * hy, -hz}, 1.0);           // upper box
      addContact(box.d, 0, 4 + i, {kOffset + sx * hx, sy * hy, kHeight}, -1.0);
      ++i;
    }
  }
  Eigen::VectorXd inverse_mass(12);
  inverse_mass << 1 / kMass, 1 / kMass, 1 / kMass,
      3 / (kMass * (kHalfY * kHalfY + kHeight * kHeight)),
      3 / (kMass * (kHalfX * kHalfX + kHeight * kHeight)),
      3 / (kMass * (kHalfX * kHalfX + kHalfY * kHalfY)), 1 / kTopMass, 1 / kTopMass, 1 / kTopMass,
      3 / (kTopMass * (hy * hy + hz * hz)), 3 / (kTopMass * (hx * hx + hz * hz)),
      3 / (kTopMass * (hx * hx + hy * hy));
  Eigen::VectorXd v_free = Eigen::VectorXd::Zero(12);
  const Eigen::Vector3d fall =
      kStep * kGravity * Eigen::Vector3d(std::sin(theta), 0, -std::cos(theta));
  v_free.segment<3>(0) = fall;
  v_free.segment<3>(6) = fall;
  finish(box, inverse_mass, v_free);
  return box;
}

// The sticking solution of a problem built by finish(), from the rigid bodies: u = N gamma + r = 0
// gives gamma = D^T lambda with (D D^T + c M) lambda = -M v_free (then N gamma + r =
// D^T (M^-1 (D D^T + c M) lambda + v_free) = 0).
Eigen::VectorXd compliantStaticSolution(const Box& box) {
  const Eigen::MatrixXd mass = box.minv.inverse();
  const Eigen::MatrixXd system = box.d * box.d.transpose() + kCompliance * mass;
  return box.d.transpose() * system.ldlt().solve(-mass * box.v_free);
}

class GlobalNewtonBox : public testing::TestWithParam<bool> {
 protected:
  const Problem& problem(const Box& box) const { return GetParam() ? box.matrix_free : box.dense; }
  // The box's problem solved to kTolerance within kBoxSweeps (global Newton steps every
  // global_newton_interval sweeps; 0: sweeps alone).
  Result solveBox(const Box& box, int global_newton_interval, Eigen::VectorXd& gamma) const {
    NsgsSettings settings;
    settings.tolerance = kTolerance;
    settings.max_iterations = kBoxSweeps;
    settings.global_newton_interval = global_newton_interval;
    NsgsSolver solver(settings);
    return solver.solve(problem(box), gamma);
  }
  void expectCompliantStaticSplit(const Box& box) const;
};

// Sweeps between global Newton steps: NsgsSettings' default.
const int kGlobalNewtonInterval = NsgsSettings{}.global_newton_interval;

// The problem's closed-form sticking solution (every contact pressed and inside its cone) is
// reached with the default global Newton steps, and within kImpulseAgreement.
void GlobalNewtonBox::expectCompliantStaticSplit(const Box& box) const {
  const Eigen::VectorXd exact = compliantStaticSolution(box);
  for (Eigen::Index i = 0; i < exact.size() / 3; ++i) {
    ASSERT_GT(exact[3 * i], 0.0) << "contact " << i;
    ASSERT_LT(exact.segment<2>(3 * i + 1).norm(), kMu * exact[3 * i]) << "contact " << i;
  }
  Eigen::VectorXd gamma;
  const Result result = solveBox(box, kGlobalNewtonInterval, gamma);
  ASSERT_EQ(result.status, Status::Converged)
      << result.iterations << " sweeps, residual " << result.residual;
  EXPECT_GE(result.global_newton_kept, 1);
  EXPECT_LE((gamma - exact).norm(), kImpulseAgreement * exact.norm());
}

TEST_P(GlobalNewtonBox, CornersOnAnInclineTakeTheCompliantStaticSplit) {
  const Box box = boxOnIncline(0.5 * std::atan(kMu));
  expectCompliantStaticSplit(box);

  // Sweeps alone, with the same budget, do not get there (the reason for the global steps).
  Eigen::VectorXd gamma_sweeps;
  EXPECT_EQ(solveBox(box, 0, gamma_sweeps).status, Status::MaxIterations);
}

TEST_P(GlobalNewtonBox, AStackOfTwoBoxesOnAnInclineTakesTheCompliantStaticSplit) {
  const Box stack = stackOnIncline(0.5 * std::atan(kMu));
  // The upper box's offset down the slope loads the lower box's downhill floor corner (2) more
  // than its uphill one (0): by 49 % of the uphill load, where the slope alone gives 30 % (the
  // same stack without the offset, and the one box), so the upper box's placement matters.
  const Eigen::VectorXd exact = compliantStaticSolution(stack);
  ASSERT_GT(exact[3 * 2] - exact[3 * 0], 0.4 * exact[3 * 0]);
  expectCompliantStaticSplit(stack);
}

TEST(GlobalNewton, MatrixFreeStepsAreTheDenseFormsOnATwoBodyStack) {
  // The matrix-free form solves its Newton systems augmented with M^-1 D (global_newton.cpp),
  // the dense form with N itself: the same steps, so the same sweeps and impulses to round-off.
  const Box stack = stackOnIncline(0.5 * std::atan(kMu));
  NsgsSettings settings;
  settings.tolerance = kTolerance;
  settings.max_iterations = kBoxSweeps;
  NsgsSolver solver(settings);
  Eigen::VectorXd dense_gamma, free_gamma;
  const Result dense = solver.solve(stack.dense, dense_gamma);
  const Result matrix_free = solver.solve(stack.matrix_free, free_gamma);
  ASSERT_GE(dense.global_newton_kept, 1);
  EXPECT_EQ(matrix_free.iterations, dense.iterations);
  EXPECT_EQ(matrix_free.global_newton_tries, dense.global_newton_tries);
  EXPECT_EQ(matrix_free.global_newton_kept, dense.global_newton_kept);
  EXPECT_LE((free_gamma - dense_gamma).norm(), 1e-9 * dense_gamma.norm());
}

TEST_P(GlobalNewtonBox, ABoxSlidingDownAnInclineHasTheExactAcceleration) {
  const double theta = 1.3 * std::atan(kMu);
  const Box box = boxOnIncline(theta);
  Eigen::VectorXd gamma;
  const Result result = solveBox(box, kGlobalNewtonInterval, gamma);
  ASSERT_EQ(result.status, Status::Converged)
      << result.iterations << " sweeps, residual " << result.residual;
  const Eigen::VectorXd v = box.v_free + box.minv * box.d * gamma;
  // Closed form with the compliance: every corner slides with u_n = v_z + (w x p)_z + c g_n = 0;
  // summed over the symmetric corners, 4 v_z + c S = 0 for the total normal impulse S, and
  // S = m (h g cos theta + v_z), so S = m h g cos theta / (1 + m c / 4); friction is -mu S
  // along the slope (-x), and the box slides at v_x = h g sin theta - mu S / m.
  const double normal_exact =
      kMass * kStep * kGravity * std::cos(theta) / (1.0 + kMass * kCompliance / 4.0);
  const double impulse_tolerance = 1e-9 * normal_exact;       // round-off of the sums
  const double velocity_tolerance = 1e-9 * kStep * kGravity;  // m/s, likewise
  double normal = 0.0, friction = 0.0;
  for (int i = 0; i < 4; ++i) {
    normal += gamma[3 * i];
    friction += gamma[3 * i + 1];
    // Every corner slides: friction on its cone's boundary, against the slip.
    EXPECT_NEAR(gamma[3 * i + 1], -kMu * gamma[3 * i], impulse_tolerance);
    EXPECT_NEAR(gamma[3 * i + 2], 0.0, impulse_tolerance);
  }
  EXPECT_NEAR(normal, normal_exact, impulse_tolerance);
  EXPECT_NEAR(friction, -kMu * normal_exact, impulse_tolerance);
  EXPECT_NEAR(v[0], kStep * kGravity * std::sin(theta) - kMu * normal_exact / kMass,
              velocity_tolerance);
  EXPECT_NEAR(v[1], 0.0, velocity_tolerance);
  EXPECT_NEAR(v[2], -kCompliance * normal_exact / 4.0, velocity_tolerance);
}

INSTANTIATE_TEST_SUITE_P(DenseAndMatrixFree, GlobalNewtonBox, testing::Bool(),
                         [](const testing::TestParamInfo<bool>& param_info) {
                           return std::string(param_info.param ? "MatrixFree" : "Dense");
                         });

TEST(GlobalNewton, TheSiconosBoxStackConvergesInFewSweeps) {
  // BoxesStack1: 13 boxes stacked, 52 coplanar corner contacts. Measured on this branch: sweeps
  // alone take 258,730 sweeps to 1e-8, with the global steps every 50 sweeps (the default) 512.
  const Problem problem =
      readFc3dFile(std::string(RHEOFEED_FC3D_DIR) + "/BoxesStack1-i100000-32.hdf5.dat");
  NsgsSettings settings;
  settings.tolerance = 1e-8;
  settings.max_iterations = 5000;  // ten times the measured need
  NsgsSolver solver(settings);
  Eigen::VectorXd gamma;
  const Result result = solver.solve(problem, gamma);
  EXPECT_EQ(result.status, Status::Converged)
      << result.iterations << " sweeps, residual " << result.residual;
  // Recomputed here from the returned impulses.
  EXPECT_LE(test::relativeResidual(problem.delassus, gamma, problem.r, problem.mu, true), 1e-8);
}

TEST(GlobalNewton, ProblemsAboveTheContactLimitTakeNoGlobalSteps) {
  NsgsSettings settings;
  settings.global_newton_max_contacts = 3;  // the box has 4
  settings.max_iterations = 200;
  NsgsSolver solver(settings);
  Eigen::VectorXd gamma;
  const Result result = solver.solve(boxOnIncline(0.1).dense, gamma);
  EXPECT_EQ(result.global_newton_tries, 0);
  EXPECT_GT(result.iterations, 2 * settings.global_newton_interval);
}

TEST(GlobalNewton, RefusesABadStepLimitByName) {
  NsgsSettings settings;
  settings.global_newton_step_limit = 0.0;
  NsgsSolver solver(settings);
  Eigen::VectorXd gamma;
  const Result result = solver.solve(boxOnIncline(0.1).dense, gamma);
  EXPECT_EQ(result.status, Status::InvalidInput);
  RHEOFEED_EXPECT_CONTAINS(result.message, "global_newton_step_limit");
}

}  // namespace
}  // namespace rheofeed::ccp
