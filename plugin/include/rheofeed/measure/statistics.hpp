// SPDX-License-Identifier: MIT
/// @file statistics.hpp
/// The statistics every published number goes through: the mean over parts (or seeds) and the
/// half-width of its two-sided 95 % confidence interval from Student's t.
#pragma once
#include <vector>

namespace rheofeed::scene {

/// Arithmetic mean of `values` (their unit); 0 for an empty list.
double mean(const std::vector<double>& values);

/// Two-sided 95 % Student-t quantile t_{0.975, dof} for `dof` degrees of freedom: the tabulated
/// value for dof 1..30 (12.706 at 1, 2.042 at 30), linear in dof between the tabulated 2.042
/// (30), 2.000 (60) and 1.980 (120) (at most 0.007 above the true quantile: a conservative
/// interval), and above 120 linear in 1 / dof between 1.980 (120) and the normal quantile 1.960
/// (dof -> infinity), 1.960 + 0.020 x 120 / dof (within 2e-4 of the true quantile); 0 for
/// dof < 1.
double studentT95(int dof);

/// Half-width of the 95 % confidence interval of the mean of `values` (their unit):
/// t_{0.975, n-1} s / sqrt(n), s the sample standard deviation (n - 1 in the denominator); 0 for
/// fewer than two values.
double ci95(const std::vector<double>& values);

/// Whether ci95 over `count` values is defined: two or more (one value has no spread; the
/// outputs write null, an empty field or n/a instead of ci95's 0).
inline bool ci95Defined(int count) {
  return count >= 2;
}

}  // namespace rheofeed::scene
