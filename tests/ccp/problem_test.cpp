// SPDX-License-Identifier: MIT
// Tests of problem.hpp: validation messages, the matrix-free Delassus blocks and the r builder.

#include "rheofeed/ccp/problem.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace rheofeed::ccp {
namespace {

// Products of O(1) entries over a few dozen terms: a few hundred ulps.
constexpr double kProductTolerance = 1e-13;

Problem smallDenseProblem() {
  std::mt19937 rng(1);
  const Eigen::Index nc = 3;
  return Problem::makeDense(test::randomSpd(3 * nc, 0.5, 2.0, rng),
                            test::randomVector(3 * nc, 1.0, rng), Eigen::Vector3d(0.5, 0.2, 0.9));
}

// Two rigid bodies (12 dofs), three contacts, random Jacobian and a block-diagonal inverse mass.
struct MatrixFreeFixture {
  SparseMatrix d;
  SparseMatrix minv;
  Eigen::MatrixXd dense_d;
  Eigen::MatrixXd dense_minv;

  MatrixFreeFixture() {
    std::mt19937 rng(2);
    dense_d = Eigen::MatrixXd::Zero(12, 9);
    // Contact 0 on body 0 only, contact 1 on body 1 only, contact 2 between both bodies.
    dense_d.block(0, 0, 6, 3) = test::randomMatrix(6, 3, rng);
    dense_d.block(6, 3, 6, 3) = test::randomMatrix(6, 3, rng);
    dense_d.block(0, 6, 12, 3) = test::randomMatrix(12, 3, rng);
    dense_minv = Eigen::MatrixXd::Zero(12, 12);
    dense_minv.block(0, 0, 6, 6) = test::randomSpd(6, 0.2, 3.0, rng);
    dense_minv.block(6, 6, 6, 6) = test::randomSpd(6, 0.2, 3.0, rng);
    d = dense_d.sparseView();
    minv = dense_minv.sparseView();
  }
};

TEST(ProblemValidation, AcceptsConsistentDenseProblem) {
  EXPECT_EQ(smallDenseProblem().validate(), "");
}

TEST(ProblemValidation, AcceptsEmptyProblem) {
  EXPECT_EQ(
      Problem::makeDense(Eigen::MatrixXd(0, 0), Eigen::VectorXd(0), Eigen::VectorXd(0)).validate(),
      "");
}

TEST(ProblemValidation, NamesNonFiniteEntryOfR) {
  Problem problem = smallDenseProblem();
  problem.r(4) = std::numeric_limits<double>::quiet_NaN();
  RHEOFEED_EXPECT_CONTAINS(problem.validate(), "r[4] = nan");
}

TEST(ProblemValidation, NamesNonFiniteEntryOfDelassus) {
  Problem problem = smallDenseProblem();
  problem.delassus(2, 7) = std::numeric_limits<double>::infinity();
  RHEOFEED_EXPECT_CONTAINS(problem.validate(), "delassus(2, 7) = inf");
}

TEST(ProblemValidation, NamesNegativeFrictionWithContactIndex) {
  Problem problem = smallDenseProblem();
  problem.mu(1) = -0.25;
  const std::string message = problem.validate();
  RHEOFEED_EXPECT_CONTAINS(message, "mu[1] = -0.25");
  RHEOFEED_EXPECT_CONTAINS(message, "contact 1");
}

TEST(ProblemValidation, NamesContactWithNonPositiveDiagonalBlock) {
  Problem problem = smallDenseProblem();
  problem.delassus.block<3, 3>(6, 6) = Eigen::Vector3d(1.0, -1.0, 1.0).asDiagonal();
  const std::string message = problem.validate();
  RHEOFEED_EXPECT_CONTAINS(message, "contact 2");
  RHEOFEED_EXPECT_CONTAINS(message, "not positive definite");
}

TEST(ProblemValidation, NamesSizeMismatch) {
  Problem problem = smallDenseProblem();
  problem.r.resize(8);
  RHEOFEED_EXPECT_CONTAINS(problem.validate(), "r has 8 entries, expected 3 * 3 contacts = 9");
  problem = smallDenseProblem();
  problem.delassus.conservativeResize(9, 8);
  RHEOFEED_EXPECT_CONTAINS(problem.validate(), "delassus is 9 x 8");
}

TEST(ProblemValidation, NamesNonPositiveInverseMassDiagonal) {
  MatrixFreeFixture f;
  f.minv.coeffRef(7, 7) = 0.0;
  const Problem problem = Problem::makeMatrixFree(f.d, f.minv, Eigen::VectorXd::Zero(9),
                                                  Eigen::Vector3d::Constant(0.5));
  RHEOFEED_EXPECT_CONTAINS(problem.validate(), "minv(7, 7) = 0");
}

TEST(ProblemValidation, NamesIndefiniteInverseMassBlock) {
  MatrixFreeFixture f;
  // Positive diagonal but indefinite: [[1, 2], [2, 1]] on dofs 6 and 7 (eigenvalues 3, -1); the
  // rest of body 1's block is diagonal, so the coupled block is dofs 6..7.
  f.dense_minv.block(6, 6, 6, 6) = Eigen::MatrixXd::Identity(6, 6);
  f.dense_minv(6, 7) = f.dense_minv(7, 6) = 2.0;
  f.minv = f.dense_minv.sparseView();
  const Problem problem = Problem::makeMatrixFree(f.d, f.minv, Eigen::VectorXd::Zero(9),
                                                  Eigen::Vector3d::Constant(0.5));
  RHEOFEED_EXPECT_CONTAINS(problem.validate(),
                           "minv diagonal block of dofs 6..7 is not positive definite");
}

TEST(ProblemValidation, NamesNonFiniteJacobianEntry) {
  MatrixFreeFixture f;
  f.d.coeffRef(3, 1) = std::numeric_limits<double>::quiet_NaN();
  const Problem problem = Problem::makeMatrixFree(f.d, f.minv, Eigen::VectorXd::Zero(9),
                                                  Eigen::Vector3d::Constant(0.5));
  RHEOFEED_EXPECT_CONTAINS(problem.validate(), "d(3, 1) = nan");
}

TEST(MatrixFreeProblem, DiagonalBlocksMatchDenseProduct) {
  MatrixFreeFixture f;
  const Problem problem = Problem::makeMatrixFree(f.d, f.minv, Eigen::VectorXd::Zero(9),
                                                  Eigen::Vector3d::Constant(0.5));
  ASSERT_EQ(problem.validate(), "");
  const Eigen::MatrixXd n = f.dense_d.transpose() * f.dense_minv * f.dense_d;
  for (Eigen::Index i = 0; i < 3; ++i) {
    EXPECT_LE((problem.diagonalBlock(i) - n.block<3, 3>(3 * i, 3 * i)).norm(),
              kProductTolerance * n.norm());
  }
  EXPECT_LE((problem.denseDelassus() - n).norm(), kProductTolerance * n.norm());
}

TEST(MatrixFreeProblem, ContactVelocityIsDelassusTimesImpulsePlusR) {
  MatrixFreeFixture f;
  std::mt19937 rng(4);
  const Eigen::VectorXd r = test::randomVector(9, 1.0, rng);
  const Eigen::VectorXd gamma = test::randomVector(9, 1.0, rng);
  const Problem problem = Problem::makeMatrixFree(f.d, f.minv, r, Eigen::Vector3d::Constant(0.5));
  const Eigen::VectorXd expected = f.dense_d.transpose() * (f.dense_minv * (f.dense_d * gamma)) + r;
  EXPECT_LE((problem.contactVelocity(gamma) - expected).norm(),
            kProductTolerance * (1.0 + expected.norm()));
}

TEST(ContactOffset, AddsNormalAndTangentialTermsToFreeVelocity) {
  MatrixFreeFixture f;
  std::mt19937 rng(6);
  const Eigen::VectorXd v_free = test::randomVector(12, 1.0, rng);
  const Eigen::Vector3d normal_term(0.1, -0.2, 0.3);
  Eigen::VectorXd tangential_term(6);
  tangential_term << 1, 2, 3, 4, 5, 6;
  Eigen::VectorXd r;
  ASSERT_EQ(buildContactOffset(f.d, v_free, normal_term, tangential_term, r), "");
  ASSERT_EQ(r.size(), 9);
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) {
      const double projected = f.dense_d.col(3 * i + k).dot(v_free);
      const double bias = k == 0 ? normal_term(i) : tangential_term(2 * i + k - 1);
      EXPECT_NEAR(r(3 * i + k), projected + bias, kProductTolerance) << "contact " << i;
    }
  }
}

TEST(ContactOffset, RefusesMismatchedSizes) {
  MatrixFreeFixture f;
  Eigen::VectorXd r = Eigen::VectorXd::Constant(2, 7.0);
  RHEOFEED_EXPECT_CONTAINS(buildContactOffset(f.d, Eigen::VectorXd::Zero(12),
                                              Eigen::Vector3d::Zero(), Eigen::VectorXd::Zero(5), r),
                           "tangential_term has 5 entries, expected 2 * 3 contacts = 6");
  RHEOFEED_EXPECT_CONTAINS(buildContactOffset(f.d, Eigen::VectorXd::Zero(11),
                                              Eigen::Vector3d::Zero(), Eigen::VectorXd::Zero(6), r),
                           "v_free has 11 entries");
  EXPECT_EQ(r.size(), 2);  // untouched on failure
}

TEST(NormalStabilisation, ClampsPenetrationRecoveryButNotGapClosing) {
  const double h = 0.01;
  EXPECT_DOUBLE_EQ(normalStabilisation(0.002, h, 0.1), 0.2);      // open gap closes in one step
  EXPECT_DOUBLE_EQ(normalStabilisation(-0.0005, h, 0.1), -0.05);  // small penetration
  EXPECT_DOUBLE_EQ(normalStabilisation(-0.01, h, 0.1), -0.1);     // clamped recovery speed
  EXPECT_DOUBLE_EQ(normalStabilisation(-0.01, h, std::numeric_limits<double>::infinity()), -1.0);
}

}  // namespace
}  // namespace rheofeed::ccp
