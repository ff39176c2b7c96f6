// SPDX-License-Identifier: MIT
// NSGS true-Coulomb solver (plugin/src/ccp/nsgs.cpp, local_coulomb.cpp): the Siconos fc3d
// problems solved to 1e-8 with the residual recomputed here, analytic single-contact motion on an
// incline, dense and matrix-free agreement, and warm starts.
#include "rheofeed/ccp/nsgs.hpp"
#include "rheofeed/ccp/fc3d_reader.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "test_support.hpp"

#ifndef RHEOFEED_FC3D_DIR
#error "RHEOFEED_FC3D_DIR must be defined to the fc3d data directory"
#endif

namespace rheofeed::ccp {
namespace {

// Required Coulomb residual (the solver's scale-invariant definition, recomputed here).
constexpr double kTolerance = 1e-8;
// Sweep budget: with sweeps alone (NsgsSettings::global_newton_interval = 0) the 13-box stack
// (BoxesStack1) takes about 2.6e5 sweeps, the slowest of the files; the budget leaves a 4x
// margin for that (the default, with global Newton steps, takes 512).
constexpr int kMaxSweeps = 1'000'000;
// Membership of the returned impulses in K: projections round at the ulp level of gamma.
constexpr double kConeRoundoff = 1e-12;
constexpr double kGravity = 9.81;  // m/s^2
constexpr double kPi = 3.14159265358979323846;

const char* const kFiles[] = {"FrictionContact3D_1c.dat",
                              "FC3D_Example1.dat",
                              "Rover4396.dat",
                              "Rover1039.dat",
                              "Rover3865.dat",
                              "NESpheres_10_1.dat",
                              "BoxesStack1-i100000-32.hdf5.dat",
                              "Capsules-i101-404.dat"};

class NsgsFc3d : public testing::TestWithParam<const char*> {};

TEST_P(NsgsFc3d, SolvesTheCoulombLawTo1e8) {
  const std::string path = std::string(RHEOFEED_FC3D_DIR) + "/" + GetParam();
  ASSERT_TRUE(std::filesystem::exists(path)) << "missing fc3d file " << path;
  const Problem problem = readFc3dFile(path);
  NsgsSettings settings;
  settings.tolerance = kTolerance;
  settings.max_iterations = kMaxSweeps;
  NsgsSolver solver(settings);
  Eigen::VectorXd gamma;
  const Result result = solver.solve(problem, gamma);
  EXPECT_EQ(result.status, Status::Converged)
      << toString(result.status) << " after " << result.iterations << " sweeps, residual "
      << result.residual << " " << result.message;
  // Recomputed here from the returned impulses, not taken from the solver.
  EXPECT_LE(test::relativeResidual(problem.delassus, gamma, problem.r, problem.mu, true),
            kTolerance);
  double violation = 0.0;
  for (Eigen::Index i = 0; i < problem.numContacts(); ++i) {
    const Eigen::Vector3d g = gamma.segment<3>(3 * i);
    violation = std::max(violation, g.tail<2>().norm() - problem.mu[i] * g[0]);
    violation = std::max(violation, -g[0]);
  }
  EXPECT_LE(violation, kConeRoundoff * (1.0 + gamma.norm()));
}

INSTANTIATE_TEST_SUITE_P(SiconosData, NsgsFc3d, testing::ValuesIn(kFiles),
                         [](const testing::TestParamInfo<const char*>& param_info) {
                           std::string name = param_info.param;
                           name = name.substr(0, name.find(".dat"));
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

// One step of a point mass m resting on an incline of angle theta (contact frame: n out of the
// plane, t1 down the slope, t2 across), with velocity zero at the start of the step of length
// h: r = h g (-cos theta, sin theta, 0), N = I / m.
Problem inclineStep(double mass, double theta, double mu, double h, bool matrix_free) {
  Eigen::VectorXd r(3);
  r << -h * kGravity * std::cos(theta), h * kGravity * std::sin(theta), 0.0;
  Eigen::VectorXd friction(1);
  friction << mu;
  if (!matrix_free) {
    return Problem::makeDense(Eigen::Matrix3d::Identity() / mass, r, friction);
  }
  SparseMatrix d(3, 3), minv(3, 3);
  d.setIdentity();
  minv.setIdentity();
  minv *= 1.0 / mass;
  return Problem::makeMatrixFree(d, minv, r, friction);
}

class NsgsIncline : public testing::TestWithParam<bool> {};

TEST_P(NsgsIncline, SticksBelowTheFrictionAngle) {
  const double mass = 2.0, mu = 0.5, h = 0.01;
  const double theta = 0.9 * std::atan(mu);
  const Problem problem = inclineStep(mass, theta, mu, h, GetParam());
  NsgsSolver solver;
  Eigen::VectorXd gamma;
  ASSERT_EQ(solver.solve(problem, gamma).status, Status::Converged);
  const Eigen::VectorXd u = problem.contactVelocity(gamma);
  // Stick: the part stays at rest; the impulses carry the weight's two components.
  EXPECT_NEAR(u.norm(), 0.0, 1e-12);
  EXPECT_NEAR(gamma[0], mass * h * kGravity * std::cos(theta), 1e-12);
  EXPECT_NEAR(gamma[1], -mass * h * kGravity * std::sin(theta), 1e-12);
  EXPECT_NEAR(gamma[2], 0.0, 1e-12);
}

TEST_P(NsgsIncline, SlidesAboveTheFrictionAngleWithTheExactAcceleration) {
  const double mass = 2.0, mu = 0.5, h = 0.01;
  const double theta = 1.3 * std::atan(mu);
  const Problem problem = inclineStep(mass, theta, mu, h, GetParam());
  NsgsSolver solver;
  Eigen::VectorXd gamma;
  ASSERT_EQ(solver.solve(problem, gamma).status, Status::Converged);
  const Eigen::VectorXd u = problem.contactVelocity(gamma);
  // Slide: no separation (true Coulomb, not the relaxation's mu |u_t|), friction mu N against
  // the slip, acceleration g (sin theta - mu cos theta) down the slope.
  const double acceleration = kGravity * (std::sin(theta) - mu * std::cos(theta));
  EXPECT_NEAR(u[0], 0.0, 1e-12);
  EXPECT_NEAR(u[1] / h, acceleration, 1e-9);
  EXPECT_NEAR(u[2], 0.0, 1e-12);
  EXPECT_NEAR(gamma[0], mass * h * kGravity * std::cos(theta), 1e-12);
  EXPECT_NEAR(gamma[1], -mu * gamma[0], 1e-12);
}

INSTANTIATE_TEST_SUITE_P(DenseAndMatrixFree, NsgsIncline, testing::Bool(),
                         [](const testing::TestParamInfo<bool>& param_info) {
                           return std::string(param_info.param ? "MatrixFree" : "Dense");
                         });

TEST(Nsgs, WarmStartFromTheSolutionOfARepeatedProblemTakesFewerSweeps) {
  const Problem problem = readFc3dFile(std::string(RHEOFEED_FC3D_DIR) + "/Capsules-i101-404.dat");
  NsgsSettings settings;
  settings.tolerance = kTolerance;
  settings.max_iterations = kMaxSweeps;
  NsgsSolver solver(settings);
  Eigen::VectorXd gamma;
  const Result cold = solver.solve(problem, gamma);
  ASSERT_EQ(cold.status, Status::Converged);
  ASSERT_GT(cold.iterations, 10);
  // The same problem again, and one whose free velocity moved by 1 %, from the last impulses.
  const Result repeated = solver.solve(problem, gamma);
  EXPECT_EQ(repeated.status, Status::Converged);
  EXPECT_EQ(repeated.iterations, 0);
  Problem moved = problem;
  moved.r *= 1.01;
  const Result warm = solver.solve(moved, gamma);
  Eigen::VectorXd zero;
  const Result cold_moved = solver.solve(moved, zero);
  EXPECT_EQ(warm.status, Status::Converged);
  EXPECT_EQ(cold_moved.status, Status::Converged);
  EXPECT_LT(warm.iterations, cold_moved.iterations / 2);
}

TEST(Nsgs, DenseAndMatrixFreeFormsGiveTheSameVelocities) {
  // Twelve contacts on four bodies (6 dofs each) with coupled rows: a random sparse D, a block
  // diagonal M^-1 of masses and inertias.
  const int bodies = 4, nc = 12;
  SparseMatrix d(6 * bodies, 3 * nc), minv(6 * bodies, 6 * bodies);
  std::srand(7);
  auto random = [] { return 2.0 * std::rand() / RAND_MAX - 1.0; };
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < nc; ++i) {
    for (int side = 0; side < 2; ++side) {
      const int body = (i + side * (1 + i % 3)) % bodies;
      for (int k = 0; k < 3; ++k) {
        for (int q = 0; q < 6; ++q) entries.emplace_back(6 * body + q, 3 * i + k, random());
      }
    }
  }
  d.setFromTriplets(entries.begin(), entries.end());
  entries.clear();
  for (int q = 0; q < 6 * bodies; ++q) entries.emplace_back(q, q, 0.5 + 0.1 * (q % 5));
  minv.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd r(3 * nc), mu(nc);
  for (int i = 0; i < 3 * nc; ++i) r[i] = random();
  for (int i = 0; i < nc; ++i) mu[i] = 0.3 + 0.05 * (i % 4);
  const Problem free_form = Problem::makeMatrixFree(d, minv, r, mu);
  const Problem dense_form = Problem::makeDense(free_form.denseDelassus(), r, mu);
  NsgsSettings settings;
  settings.tolerance = 1e-12;
  settings.max_iterations = kMaxSweeps;
  Eigen::VectorXd gamma_dense, gamma_free;
  NsgsSolver dense_solver(settings), free_solver(settings);
  ASSERT_EQ(dense_solver.solve(dense_form, gamma_dense).status, Status::Converged);
  ASSERT_EQ(free_solver.solve(free_form, gamma_free).status, Status::Converged);
  const Eigen::VectorXd u_dense = dense_form.contactVelocity(gamma_dense);
  const Eigen::VectorXd u_free = dense_form.contactVelocity(gamma_free);
  // Same sweep order and arithmetic up to round-off: velocities agree far below the tolerance
  // times their scale.
  EXPECT_LE((u_dense - u_free).norm(), 1e-9 * (1.0 + r.norm()));
}

TEST(Nsgs, RefusesBadSettingsWithTheirName) {
  NsgsSettings settings;
  settings.omega = 2.5;
  NsgsSolver solver(settings);
  Eigen::VectorXd gamma;
  const Problem problem = inclineStep(1.0, 0.1, 0.5, 0.01, false);
  const Result result = solver.solve(problem, gamma);
  EXPECT_EQ(result.status, Status::InvalidInput);
  RHEOFEED_EXPECT_CONTAINS(result.message, "omega");
}

TEST(Nsgs, ResultStartsAtNotRun) {
  EXPECT_STREQ(toString(Result{}.status), "NotRun");
  EXPECT_STREQ(toString(ContactOrder::Shuffled), "Shuffled");
}

}  // namespace
}  // namespace rheofeed::ccp
