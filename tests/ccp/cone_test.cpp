// SPDX-License-Identifier: MIT
// Tests of cone.hpp: projections onto the friction cone, its polar and its dual.

#include "rheofeed/ccp/cone.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace rheofeed::ccp {
namespace {

// A handful of roundings in a 3-vector computation: relative error bound for sums, dot products
// and membership tests of unit-scale vectors.
constexpr double kRoundoff = 64.0 * std::numeric_limits<double>::epsilon();
constexpr int kSamples = 2000;

// Friction coefficients covering frictionless, usual, large and extreme values.
const std::vector<double> kFrictions = {0.0, 1e-3, 0.3, 1.0, 3.0, 1e3, 1e8};

// Random points of all directions and of magnitudes from 1e-6 to 1e6, plus points near the
// cone's axis and boundary, where the branches of the projection meet.
std::vector<Eigen::Vector3d> samplePoints(double mu, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> exponent(-6.0, 6.0);
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < kSamples; ++k) {
    Eigen::Vector3d x(normal(rng), normal(rng), normal(rng));
    points.push_back(x * std::pow(10.0, exponent(rng)));
  }
  const Eigen::Vector3d axis(1.0, 0.0, 0.0);
  points.push_back(axis);
  points.push_back(-axis);
  points.push_back(Eigen::Vector3d::Zero());
  points.push_back(Eigen::Vector3d(0.0, 1.0, 0.0));
  points.push_back(Eigen::Vector3d(1.0, mu, 0.0));      // on K's boundary
  points.push_back(Eigen::Vector3d(-mu, 0.0, 1.0));     // on the polar's boundary
  points.push_back(Eigen::Vector3d(1.0, 0.0, 1e-300));  // almost on the axis
  return points;
}

bool inCone(const Eigen::Vector3d& x, double mu, double tolerance) {
  return std::hypot(x(1), x(2)) <= mu * x(0) + tolerance;
}

bool inPolarCone(const Eigen::Vector3d& x, double mu, double tolerance) {
  return x(0) + mu * std::hypot(x(1), x(2)) <= tolerance;
}

TEST(ConeProjection, MoreauDecompositionHolds) {
  std::mt19937 rng(42);
  for (double mu : kFrictions) {
    for (const Eigen::Vector3d& x : samplePoints(mu, rng)) {
      SCOPED_TRACE(testing::Message() << "mu = " << mu << ", x = " << x.transpose());
      const Eigen::Vector3d p = projectOntoCone(x, mu);
      const Eigen::Vector3d q = projectOntoPolarCone(x, mu);
      const double scale = x.norm();
      EXPECT_LE((p + q - x).norm(), kRoundoff * scale);
      EXPECT_LE(std::abs(p.dot(q)), kRoundoff * scale * scale);
      EXPECT_TRUE(inCone(p, mu, kRoundoff * scale * (1.0 + mu)));
      EXPECT_TRUE(inPolarCone(q, mu, kRoundoff * scale * (1.0 + mu)));
    }
  }
}

TEST(ConeProjection, IsIdempotentAndLandsInCone) {
  std::mt19937 rng(7);
  for (double mu : kFrictions) {
    for (const Eigen::Vector3d& x : samplePoints(mu, rng)) {
      SCOPED_TRACE(testing::Message() << "mu = " << mu << ", x = " << x.transpose());
      const Eigen::Vector3d p = projectOntoCone(x, mu);
      ASSERT_TRUE(p.allFinite());
      EXPECT_TRUE(inCone(p, mu, kRoundoff * x.norm() * (1.0 + mu)));
      EXPECT_LE((projectOntoCone(p, mu) - p).norm(), kRoundoff * x.norm());
    }
  }
}

TEST(ConeProjection, MatchesTextbookFormula) {
  std::mt19937 rng(3);
  for (double mu : {0.0, 0.1, 0.7, 2.0, 50.0}) {
    for (const Eigen::Vector3d& x : samplePoints(mu, rng)) {
      SCOPED_TRACE(testing::Message() << "mu = " << mu << ", x = " << x.transpose());
      EXPECT_LE((projectOntoCone(x, mu) - test::referenceConeProjection(x, mu)).norm(),
                kRoundoff * x.norm());
    }
  }
}

TEST(ConeProjection, FrictionlessConeIsTheNormalHalfLine) {
  std::mt19937 rng(11);
  for (const Eigen::Vector3d& x : samplePoints(0.0, rng)) {
    const Eigen::Vector3d p = projectOntoCone(x, 0.0);
    EXPECT_EQ(p(0), std::max(x(0), 0.0));
    EXPECT_EQ(p(1), 0.0);
    EXPECT_EQ(p(2), 0.0);
  }
}

TEST(ConeProjection, HugeFrictionStaysFiniteAndTendsToHalfSpace) {
  // As mu grows, K_mu tends to the half space n >= 0, whose projection is (max(n, 0), t).
  for (double mu : {1e8, 1e150, 1e200, 1e300, std::numeric_limits<double>::max()}) {
    for (const Eigen::Vector3d& x :
         {Eigen::Vector3d(0.0, 3.0, -4.0), Eigen::Vector3d(-2.0, 3.0, -4.0),
          Eigen::Vector3d(2.0, 3.0, -4.0), Eigen::Vector3d(-2.0, 0.0, 0.0),
          Eigen::Vector3d(1e-300, 1.0, 0.0)}) {
      SCOPED_TRACE(testing::Message() << "mu = " << mu << ", x = " << x.transpose());
      const Eigen::Vector3d p = projectOntoCone(x, mu);
      const Eigen::Vector3d q = projectOntoPolarCone(x, mu);
      ASSERT_TRUE(p.allFinite());
      ASSERT_TRUE(q.allFinite());
      const Eigen::Vector3d half_space(std::max(x(0), 0.0), x(1), x(2));
      // Distance between K_mu and the half space near x is about ||x|| / mu.
      EXPECT_LE((p - half_space).norm(), kRoundoff * x.norm() + 10.0 * x.norm() / mu);
      EXPECT_LE((p + q - x).norm(), kRoundoff * x.norm());
    }
  }
}

TEST(DualCone, DistanceIsZeroInsideAndMatchesProjection) {
  std::mt19937 rng(5);
  for (double mu : kFrictions) {
    for (const Eigen::Vector3d& x : samplePoints(mu, rng)) {
      SCOPED_TRACE(testing::Message() << "mu = " << mu << ", x = " << x.transpose());
      const Eigen::Vector3d p = projectOntoDualCone(x, mu);
      // The dual cone is {mu ||t|| <= n}.
      EXPECT_LE(mu * std::hypot(p(1), p(2)), p(0) + kRoundoff * x.norm() * (1.0 + mu));
      EXPECT_NEAR(distanceToDualCone(x, mu), (x - p).norm(), kRoundoff * x.norm());
      const bool inside = mu * std::hypot(x(1), x(2)) <= x(0);
      if (inside) {
        EXPECT_EQ(distanceToDualCone(x, mu), 0.0);
      }
    }
  }
}

}  // namespace
}  // namespace rheofeed::ccp
