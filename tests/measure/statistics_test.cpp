// SPDX-License-Identifier: MIT
// statistics.cpp: the mean, Student's t quantile and the 95 % interval that every published
// drift goes through, against values from outside the code: the two-sided 95 % quantiles
// t_{0.975, dof} of the standard tables (e.g. NIST/SEMATECH e-Handbook of Statistical Methods,
// section 1.3.6.7.2, to three decimals) and intervals computed by hand.
#include "rheofeed/measure/statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace rheofeed::scene {
namespace {

// The table gives three decimals: a quantile read from it is exact to half a unit of the last.
constexpr double kTableRounding = 5e-4;
// Between the tabulated 30, 60 and 120 degrees of freedom studentT95 is linear in dof; the true
// quantile is convex in dof, so the line lies above it (a slightly wider, conservative interval)
// by at most 0.007 (at dof 40: 2.028 against 2.021).
constexpr double kInterpolationExcess = 0.008;
// Sums of a few small numbers: only rounding differs from the hand computation.
constexpr double kRounding = 1e-12;

struct Quantile {
  int dof;
  double t;  // t_{0.975, dof} from the table
};

TEST(Statistics, StudentT95MatchesTheTableForOneToThirtyDegreesOfFreedom) {
  const Quantile table[] = {{1, 12.706}, {2, 4.303},  {3, 3.182},  {4, 2.776},  {5, 2.571},
                            {6, 2.447},  {7, 2.365},  {8, 2.306},  {9, 2.262},  {10, 2.228},
                            {15, 2.131}, {20, 2.086}, {25, 2.060}, {29, 2.045}, {30, 2.042}};
  for (const Quantile& q : table) {
    EXPECT_NEAR(studentT95(q.dof), q.t, kTableRounding) << "dof " << q.dof;
  }
}

TEST(Statistics, StudentT95MatchesTheTableAtSixtyAndOneHundredTwenty) {
  EXPECT_NEAR(studentT95(60), 2.000, kTableRounding);
  EXPECT_NEAR(studentT95(120), 1.980, kTableRounding);
}

TEST(Statistics, StudentT95InterpolatesConservativelyBetweenTabulatedDegreesOfFreedom) {
  const Quantile table[] = {{40, 2.021}, {50, 2.009}, {80, 1.990}, {100, 1.984}};
  for (const Quantile& q : table) {
    const double t = studentT95(q.dof);
    EXPECT_GE(t, q.t - kTableRounding) << "dof " << q.dof << ": narrower than the true interval";
    EXPECT_LE(t, q.t + kInterpolationExcess) << "dof " << q.dof;
  }
  // Monotone: more degrees of freedom never widen the interval.
  for (int dof = 1; dof < 400; ++dof) {
    EXPECT_LE(studentT95(dof + 1), studentT95(dof)) << "dof " << dof;
  }
}

TEST(Statistics, StudentT95TendsToTheNormalQuantileBeyondTheTable) {
  // Beyond 120 degrees of freedom (more than 121 parts): 1.980 (121), 1.972 (200), 1.962 (1000),
  // and the normal quantile 1.960 in the limit. No jump from 1.980 at 120 to 1.960 at 121.
  const Quantile table[] = {{121, 1.980}, {200, 1.972}, {1000, 1.962}, {1000000, 1.960}};
  for (const Quantile& q : table) {
    EXPECT_NEAR(studentT95(q.dof), q.t, kTableRounding) << "dof " << q.dof;
  }
}

TEST(Statistics, StudentT95IsZeroWithoutDegreesOfFreedom) {
  EXPECT_EQ(studentT95(0), 0.0);
  EXPECT_EQ(studentT95(-3), 0.0);
}

TEST(Statistics, MeanIsTheArithmeticMean) {
  EXPECT_NEAR(mean({1, 2, 3, 4}), 2.5, kRounding);
  EXPECT_NEAR(mean({-0.02, 0.05, 0.03}), 0.02, kRounding);
  EXPECT_EQ(mean({7.5}), 7.5);
  EXPECT_EQ(mean({}), 0.0);
}

TEST(Statistics, Ci95IsTTimesTheStandardErrorOfTheMean) {
  // {1, 2, 3, 4, 5}: mean 3, squared deviations 4 + 1 + 0 + 1 + 4 = 10, s = sqrt(10 / 4),
  // s / sqrt(5) = sqrt(1 / 2); t_{0.975, 4} = 2.776 (table): 2.776 x 0.70710678 = 1.96292843.
  EXPECT_NEAR(ci95({1, 2, 3, 4, 5}), 1.96292843, 1e-8);
  // Two values 0.10 and 0.14 m/s: s = 0.02 sqrt(2), s / sqrt(2) = 0.02; t_{0.975, 1} = 12.706.
  EXPECT_NEAR(ci95({0.10, 0.14}), 12.706 * 0.02, kRounding);
  // Shifting every value moves the mean, not the interval.
  EXPECT_NEAR(ci95({101, 102, 103, 104, 105}), 1.96292843, 1e-8);
}

TEST(Statistics, Ci95IsZeroForFewerThanTwoValuesOrNoSpread) {
  EXPECT_EQ(ci95({}), 0.0);
  EXPECT_EQ(ci95({0.3}), 0.0);
  EXPECT_EQ(ci95({0.25, 0.25, 0.25}), 0.0);
}

}  // namespace
}  // namespace rheofeed::scene
