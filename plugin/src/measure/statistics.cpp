// SPDX-License-Identifier: MIT
#include "rheofeed/measure/statistics.hpp"

#include <cmath>

namespace rheofeed::scene {

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / v.size();
}

double studentT95(int dof) {
  // Two-sided 95 % quantiles of Student's t.
  static const double table[] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306,
                                 2.262,  2.228, 2.201, 2.179, 2.160, 2.145, 2.131, 2.120,
                                 2.110,  2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
                                 2.060,  2.056, 2.052, 2.048, 2.045, 2.042};
  if (dof < 1) return 0;
  if (dof <= 30) return table[dof - 1];
  if (dof <= 60) return 2.042 + (2.000 - 2.042) * (dof - 30) / 30.0;
  if (dof <= 120) return 2.000 + (1.980 - 2.000) * (dof - 60) / 60.0;
  // Beyond the table the quantile approaches the normal one as 1 / dof (its expansion in 1 / dof
  // starts z + (z^3 + z) / (4 dof)): interpolating in 120 / dof is what the tables prescribe.
  return 1.960 + (1.980 - 1.960) * 120.0 / dof;
}

double ci95(const std::vector<double>& v) {
  if (v.size() < 2) return 0;
  const double m = mean(v);
  double ss = 0;
  for (double x : v) ss += (x - m) * (x - m);
  const double sd = std::sqrt(ss / (v.size() - 1));
  return studentT95(static_cast<int>(v.size()) - 1) * sd / std::sqrt(double(v.size()));
}

}  // namespace rheofeed::scene
