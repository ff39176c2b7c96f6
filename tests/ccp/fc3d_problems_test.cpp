// SPDX-License-Identifier: MIT
// Both solvers on every Siconos fc3d problem of tests/data/fc3d (see its README): the relaxed
// natural map residual, recomputed here from the returned impulses, must reach 1e-8, and PGS and
// APGD must agree on the velocities u = W gamma + q and on the objective (gamma itself is not
// unique: W is rank deficient in the box stack and the Capsules problem).

#include "rheofeed/ccp/fc3d_reader.hpp"
#include "rheofeed/ccp/solver.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#ifndef RHEOFEED_FC3D_DIR
#error "RHEOFEED_FC3D_DIR must be defined to the fc3d data directory"
#endif

namespace rheofeed::ccp {
namespace {

namespace fs = std::filesystem;

// Required relaxed natural map residual (scaled by 1 + ||q||, rho = 1). Every file reaches it
// with both solvers; the floors measured with tolerance 0 are 1e-15 or below (round-off).
constexpr double kResidualTarget = 1e-8;
// Iteration budgets. PGS converges slowly on the 13-box stack (about 5.1e5 sweeps of 3.5 us at
// -O2, ~1.8 s); APGD needs a few thousand iterations there. The budgets leave a 4x margin.
constexpr int kPgsMaxSweeps = 2'000'000;
constexpr int kApgdMaxIterations = 100'000;
// Agreement of the two solvers. u is unique but W is not positive definite here (rank
// deficient box stack and Capsules, nearly singular Rovers), so no a-priori bound turns the
// residual into a velocity error (the monotone-VI bound used in solver_test.cpp needs
// lambda_min(W) > 0, and the Hoelder-type bound is vacuous for the box stack, whose ||W - I||
// is 2.7e3). The tolerance is therefore argued: where a contact sticks, its natural map
// component is u_i itself; where it separates, it is gamma_i; where it slides, a combination.
// So each solution's velocities are within a small multiple of its residual of the exact ones,
// and 100 times the residual target covers propagation through W for these problems. Measured
// differences are at most 5e-8 (Capsules).
constexpr double kVelocityAgreement = 100.0 * kResidualTarget;
// Objectives, relative to 1 + |f|: near a solution the objective error is first order in the
// impulse error with coefficient u, and u . delta_gamma is of the order of the complementarity
// error, itself of the order of the residual times ||gamma|| + ||u||; relative to 1 + |f| that
// is at most about the residual target for these problems. Measured differences are at most
// 1e-11.
constexpr double kObjectiveAgreement = kResidualTarget;
// True Coulomb mode (APGD): the Coulomb natural map residual recomputed from the returned
// impulses. Its sources: the last inner solve's relaxed residual (<= kResidualTarget relative to
// 1 + ||q + s e_n||, where the shift s = mu ||u_t|| raises that norm by a factor of at most 1.28
// on these problems) plus the last change of the shift (<= kCoulombShiftTolerance, and the
// natural map is 1-Lipschitz in u); measured values are at most 1.2e-8.
constexpr double kCoulombShiftTolerance = 1e-9;
constexpr double kCoulombResidual = 2.0 * kResidualTarget;
constexpr int kCoulombOuterIterations = 200;

// Membership of the returned impulses in K: projections round at the ulp level of gamma.
constexpr double kConeRoundoff = 1e-12;

struct Fc3dCase {
  const char* file;
  Eigen::Index contacts;
};

// The files listed in the data README.
const Fc3dCase kCases[] = {
    {"FrictionContact3D_1c.dat", 1},
    {"FC3D_Example1.dat", 3},
    {"Rover4396.dat", 2},
    {"Rover1039.dat", 4},
    {"Rover3865.dat", 5},
    {"NESpheres_10_1.dat", 9},
    {"BoxesStack1-i100000-32.hdf5.dat", 52},
    {"Capsules-i101-404.dat", 225},
};

// Names the case in gtest's output instead of dumping its bytes.
void PrintTo(const Fc3dCase& c, std::ostream* os) {
  *os << c.file;
}

fs::path dataDir() {
  return fs::path(RHEOFEED_FC3D_DIR);
}

TEST(Fc3dData, DirectoryHoldsExactlyTheKnownProblems) {
  ASSERT_TRUE(fs::is_directory(dataDir()))
      << "fc3d data directory not found: " << dataDir()
      << " (configure with -DRHEOFEED_FC3D_DIR=<folder of the .dat files>)";
  std::vector<std::string> found;
  for (const fs::directory_entry& entry : fs::directory_iterator(dataDir())) {
    if (entry.path().extension() == ".dat") found.push_back(entry.path().filename().string());
  }
  std::vector<std::string> known;
  for (const Fc3dCase& c : kCases) known.push_back(c.file);
  std::sort(found.begin(), found.end());
  std::sort(known.begin(), known.end());
  EXPECT_EQ(found, known) << "every .dat file must be covered by this test";
}

class Fc3dProblem : public testing::TestWithParam<Fc3dCase> {
 protected:
  void SetUp() override {
    const fs::path path = dataDir() / GetParam().file;
    ASSERT_TRUE(fs::is_regular_file(path)) << "fc3d problem not found: " << path;
    problem_ = readFc3dFile(path.string());
  }

  Problem problem_;
};

TEST_P(Fc3dProblem, ReadsWithTheDocumentedSize) {
  EXPECT_EQ(problem_.numContacts(), GetParam().contacts);
  EXPECT_EQ(problem_.validate(), "");
}

TEST_P(Fc3dProblem, PgsAndApgdReachResidualAndAgreeOnVelocities) {
  const Eigen::MatrixXd& w = problem_.delassus;
  const Eigen::VectorXd& q = problem_.r;
  const Eigen::VectorXd& mu = problem_.mu;
  Eigen::VectorXd velocities[2];
  double objectives[2];
  int k = 0;
  for (Method method : {Method::Pgs, Method::Apgd}) {
    SCOPED_TRACE(toString(method));
    Settings settings;
    settings.method = method;
    settings.tolerance = kResidualTarget;
    settings.max_iterations = method == Method::Pgs ? kPgsMaxSweeps : kApgdMaxIterations;
    Solver solver(settings);
    Eigen::VectorXd gamma;
    const Result result = solver.solve(problem_, gamma);
    EXPECT_EQ(result.status, Status::Converged)
        << toString(result.status) << " after " << result.iterations << " iterations, residual "
        << result.residual << " " << result.message;
    // Recomputed here, not taken from the solver.
    const Eigen::VectorXd u = w * gamma + q;
    EXPECT_LE(test::naturalMapResidual(gamma, u, mu, q), kResidualTarget);
    EXPECT_LE(test::coneViolation(gamma, mu), kConeRoundoff * (1.0 + gamma.norm()));
    velocities[k] = u;
    objectives[k] = 0.5 * gamma.dot(w * gamma) + q.dot(gamma);
    ++k;
  }
  EXPECT_LE((velocities[0] - velocities[1]).norm() / (1.0 + q.norm()), kVelocityAgreement);
  EXPECT_LE(std::abs(objectives[0] - objectives[1]) / (1.0 + std::abs(objectives[1])),
            kObjectiveAgreement);
}

TEST_P(Fc3dProblem, ApgdCoulombModeSolvesTheCoulombLaw) {
  // The fc3d problems are Coulomb problems (Siconos solves the true law); the outer fixed point
  // of Coulomb mode must reach it where the relaxed solution slides.
  Settings settings;
  settings.method = Method::Apgd;
  settings.tolerance = kResidualTarget;
  settings.max_iterations = kApgdMaxIterations;
  settings.coulomb_outer_iterations = kCoulombOuterIterations;
  settings.coulomb_tolerance = kCoulombShiftTolerance;
  Solver solver(settings);
  Eigen::VectorXd gamma;
  const Result result = solver.solve(problem_, gamma);
  EXPECT_EQ(result.status, Status::Converged)
      << toString(result.status) << " after " << result.outer_iterations << " outer iterations "
      << result.message;
  const Eigen::VectorXd u = problem_.delassus * gamma + problem_.r;
  EXPECT_LE(test::coulombResidual(gamma, u, problem_.mu, problem_.r), kCoulombResidual);
  EXPECT_LE(test::coneViolation(gamma, problem_.mu), kConeRoundoff * (1.0 + gamma.norm()));
}

INSTANTIATE_TEST_SUITE_P(SiconosData, Fc3dProblem, testing::ValuesIn(kCases),
                         [](const testing::TestParamInfo<Fc3dCase>& param_info) {
                           std::string name = param_info.param.file;
                           name = name.substr(0, name.find(".dat"));
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

}  // namespace
}  // namespace rheofeed::ccp
