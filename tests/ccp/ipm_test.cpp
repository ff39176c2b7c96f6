// SPDX-License-Identifier: MIT
// Interior-point solver (plugin/src/ccp/ipm.cpp): the relaxed CCP of the Siconos fc3d problems
// to 1e-8 with the optimality conditions recomputed here, the true Coulomb law of a mass on an
// incline against its closed form (dense and matrix-free), agreement of the two forms on a
// coupled problem, and the refusals.
#include "rheofeed/ccp/ipm.hpp"
#include "rheofeed/ccp/fc3d_reader.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "test_support.hpp"

#ifndef RHEOFEED_FC3D_DIR
#error "RHEOFEED_FC3D_DIR must be defined to the fc3d data directory"
#endif

namespace rheofeed::ccp {
namespace {

constexpr double kTolerance = 1e-8;
// Interior iterates: inside K up to the ulp level of gamma.
constexpr double kConeRoundoff = 1e-12;
constexpr double kGravity = 9.81;  // m/s^2

class IpmFc3d : public testing::TestWithParam<const char*> {};

TEST_P(IpmFc3d, SolvesTheRelaxedProblemTo1e8) {
  const std::string path = std::string(RHEOFEED_FC3D_DIR) + "/" + GetParam();
  ASSERT_TRUE(std::filesystem::exists(path)) << "missing fc3d file " << path;
  const Problem problem = readFc3dFile(path);
  IpmSettings settings;
  settings.tolerance = kTolerance;
  IpmSolver solver(settings);
  Eigen::VectorXd gamma;
  const Result result =
      solver.solveConvex(problem, Eigen::VectorXd::Zero(problem.numContacts()), gamma);
  EXPECT_EQ(result.status, Status::Converged)
      << toString(result.status) << " after " << result.iterations << " iterations, residual "
      << result.residual << " " << result.message;
  // Recomputed here: the relaxed natural map, and gamma in K.
  EXPECT_LE(test::relativeResidual(problem.delassus, gamma, problem.r, problem.mu, false),
            kTolerance);
  EXPECT_LE(test::coneViolation(gamma, problem.mu), kConeRoundoff * (1.0 + gamma.norm()));
  // An interior-point method's count does not grow with the conditioning: all of these, from
  // 1 to 225 contacts, take a few dozen.
  EXPECT_LE(result.iterations, 60);
}

INSTANTIATE_TEST_SUITE_P(SiconosData, IpmFc3d, testing::ValuesIn(test::kFc3dFiles),
                         test::fc3dTestName);

using test::inclineStep;

class IpmIncline : public testing::TestWithParam<bool> {};

// Steps of the main demo that NSGS, the reference world's solver, leaves above the scene's
// Coulomb tolerance 1e-6 (tests/data/trough_steps): the interior-point fixed point meets it, the
// residual recomputed here with De Saxce's velocity.
class IpmTroughStep : public testing::TestWithParam<const char*> {};

TEST_P(IpmTroughStep, MeetsTheSceneToleranceWhereNsgsStalls) {
  const std::string path = std::string(RHEOFEED_FC3D_DIR) + "/../trough_steps/" + GetParam();
  ASSERT_TRUE(std::filesystem::exists(path)) << "missing " << path;
  const Problem problem = readFc3dFile(path);
  IpmSettings settings;
  settings.tolerance = 1e-6;
  IpmSolver solver(settings);
  Eigen::VectorXd gamma;
  const Result result = solver.solve(problem, gamma);
  EXPECT_EQ(result.status, Status::Converged)
      << toString(result.status) << " after " << result.outer_iterations << " outer iterations, "
      << result.coulomb_distance << " " << result.message;
  EXPECT_LE(test::relativeResidual(problem.delassus, gamma, problem.r, problem.mu, true), 1e-6);
  EXPECT_LE(test::coneViolation(gamma, problem.mu), kConeRoundoff * (1.0 + gamma.norm()));
}

INSTANTIATE_TEST_SUITE_P(MainDemo, IpmTroughStep,
                         testing::Values("trough_fail_0.40.dat", "trough_fail_1.38.dat"),
                         test::fc3dTestName);

// Tolerances: 1e-10 of the weight's impulse and of h g, 1e-8 g on the acceleration (the solve
// asks for a residual of 1e-12).
void expectIncline(double theta, bool matrix_free, bool sliding) {
  const double mass = 2.0, mu = 0.5, h = 0.01;
  const Problem problem = inclineStep(mass, theta, mu, h, matrix_free);
  IpmSettings settings;
  settings.tolerance = 1e-12;
  IpmSolver solver(settings);
  Eigen::VectorXd gamma;
  const Result result = solver.solve(problem, gamma);
  ASSERT_EQ(result.status, Status::Converged) << result.message;
  // Sliding needs more than one convex solve: the first (shift 0) separates the sliding mass at
  // mu |u_t|, the true law does not.
  if (sliding) {
    EXPECT_GT(result.outer_iterations, 1);
  }
  test::expectInclineLaw(problem, gamma, mass, theta, mu, h, 1e-10 * mass * h * kGravity,
                         1e-10 * h * kGravity, 1e-8 * kGravity);
}

TEST_P(IpmIncline, SticksBelowTheFrictionAngle) {
  expectIncline(0.9 * std::atan(0.5), GetParam(), false);
}

TEST_P(IpmIncline, SlidesAboveTheFrictionAngleWithTheExactAcceleration) {
  expectIncline(1.3 * std::atan(0.5), GetParam(), true);
}

INSTANTIATE_TEST_SUITE_P(DenseAndMatrixFree, IpmIncline, testing::Bool(), test::formName);

TEST(Ipm, DenseAndMatrixFreeFormsGiveTheSameRelaxedVelocities) {
  // Twelve contacts on four bodies (6 dofs each), coupled, plus the reference world's compliance
  // c = cfm / h on N's diagonal, entered matrix-free as it does (reference/world_contacts.cpp):
  // one virtual unit-mass coordinate per contact row with D entry sqrt(c). D^T M^-1 D alone has
  // rank 24 of 36; with c the problem is strictly convex and its solution unique.
  const int nc = 12;
  const double compliance = 1e-3;  // 1/kg
  const Problem free_form = test::coupledProblem(4, nc, compliance);
  const Eigen::VectorXd& r = free_form.r;
  const Eigen::VectorXd& mu = free_form.mu;
  const Problem dense_form = Problem::makeDense(free_form.denseDelassus(), r, mu);
  // The method's floor in double precision is near 1e-9 here (the dense solve measured 1.7e-9
  // when asked for 1e-10), so the test asks for the 1e-8 of the fc3d tests.
  IpmSettings settings;
  settings.tolerance = kTolerance;
  IpmSolver dense_solver(settings), free_solver(settings);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(nc);
  Eigen::VectorXd gamma_dense, gamma_free;
  const Result dense = dense_solver.solveConvex(dense_form, zero, gamma_dense);
  const Result free = free_solver.solveConvex(free_form, zero, gamma_free);
  ASSERT_EQ(dense.status, Status::Converged) << dense.residual << " after " << dense.iterations;
  ASSERT_EQ(free.status, Status::Converged) << free.residual << " after " << free.iterations;
  EXPECT_LE(test::relativeResidual(dense_form.delassus, gamma_free, r, mu, false), kTolerance);
  EXPECT_LE(test::relativeResidual(dense_form.delassus, gamma_dense, r, mu, false), kTolerance);
  // The same unique solution, within what the residuals allow: a natural-map error e moves the
  // impulses by at most about e / c (N's smallest eigenvalue is c) and the velocities by e.
  const double e = kTolerance * r.norm();
  EXPECT_LE((gamma_dense - gamma_free).norm(), 4.0 * e / compliance);
  EXPECT_LE(
      (dense_form.contactVelocity(gamma_dense) - dense_form.contactVelocity(gamma_free)).norm(),
      4.0 * e * (1.0 + dense_form.delassus.norm() / compliance));
}

TEST(Ipm, RefusesFrictionlessContactsBadShiftsAndBadSettingsNamingThem) {
  Eigen::VectorXd r(6), mu(2), gamma;
  r << -1, 0.1, 0, -1, 0, 0.2;
  mu << 0.4, 0.0;
  const Problem problem = Problem::makeDense(Eigen::MatrixXd::Identity(6, 6), r, mu);
  IpmSolver solver;
  Result result = solver.solve(problem, gamma);
  EXPECT_EQ(result.status, Status::InvalidInput);
  EXPECT_NE(result.message.find("contact 1 has mu = 0"), std::string::npos) << result.message;

  mu << 0.4, 0.3;
  const Problem rough = Problem::makeDense(Eigen::MatrixXd::Identity(6, 6), r, mu);
  Eigen::VectorXd shift(2);
  shift << 0.0, -1.0;
  result = solver.solveConvex(rough, shift, gamma);
  EXPECT_EQ(result.status, Status::InvalidInput);
  EXPECT_NE(result.message.find("shift"), std::string::npos) << result.message;

  solver.settings().inner_tolerance_share = 0.0;
  result = solver.solve(rough, gamma);
  EXPECT_EQ(result.status, Status::InvalidInput);
  EXPECT_NE(result.message.find("inner_tolerance_share = 0"), std::string::npos) << result.message;
}

}  // namespace
}  // namespace rheofeed::ccp
