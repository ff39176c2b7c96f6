// SPDX-License-Identifier: MIT
#pragma once

// Helpers shared by the CCP tests. They are deliberately independent of the code under test:
// the cone projection here is the textbook formula, and residuals are recomputed from the
// returned impulses with the test's own products.

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

/// Expects `needle` to be a substring of the string `haystack` (gtest's IsSubstring, so the
/// failure message shows both).
#define RHEOFEED_EXPECT_CONTAINS(haystack, needle) \
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, needle, haystack)

namespace rheofeed::ccp::test {

/// Textbook projection onto K_mu = {||t|| <= mu n} (NOTES section 3), written independently of
/// cone.hpp: inside keep, in the polar cone 0, else n' = (mu s + n) / (1 + mu^2),
/// t' = mu n' t / s ("inside" needs n >= 0 for mu = 0, where mu n = -0 for n < 0). Only for
/// moderate mu (mu^2 must not overflow).
inline Eigen::Vector3d referenceConeProjection(const Eigen::Vector3d& x, double mu) {
  const double n = x(0);
  const double s = std::hypot(x(1), x(2));
  if (s <= mu * n && n >= 0.0) return x;
  if (mu * s <= -n) return Eigen::Vector3d::Zero();
  const double normal = (mu * s + n) / (1.0 + mu * mu);
  return Eigen::Vector3d(normal, mu * normal * x(1) / s, mu * normal * x(2) / s);
}

/// Unscaled natural map ||gamma - Pi_K(gamma - u)|| (rho = 1), with u supplied by the caller.
inline double naturalMap(const Eigen::VectorXd& gamma, const Eigen::VectorXd& u,
                         const Eigen::VectorXd& mu) {
  double sum = 0.0;
  for (Eigen::Index i = 0; i < mu.size(); ++i) {
    const Eigen::Vector3d g = gamma.segment<3>(3 * i);
    sum += (g - referenceConeProjection(g - u.segment<3>(3 * i), mu(i))).squaredNorm();
  }
  return std::sqrt(sum);
}

/// Natural map residual ||gamma - Pi_K(gamma - u)|| / (1 + ||r||) (rho = 1, the solver's
/// default and normalisation), with u supplied by the caller.
inline double naturalMapResidual(const Eigen::VectorXd& gamma, const Eigen::VectorXd& u,
                                 const Eigen::VectorXd& mu, const Eigen::VectorXd& r) {
  return naturalMap(gamma, u, mu) / (1.0 + r.norm());
}

/// The solver's relative residual (solver.hpp, Result::residual) recomputed for a dense N with
/// rho = 1: per contact the step s_i = 3 / trace(N_ii) (kg) and the velocity-form natural map
/// v_i = (gamma_i - Pi_K(gamma_i - s_i u_i)) / s_i (m/s); the result is
/// ||v|| / max(||r||, ||u - r||) (dimensionless; 0 when v = 0). With `coulomb`, u_n is replaced by
/// De Saxce's u_n + mu ||u_t||. Plain sums of squares: only for data whose squares neither
/// overflow nor underflow.
inline double relativeResidual(const Eigen::MatrixXd& n, const Eigen::VectorXd& gamma,
                               const Eigen::VectorXd& r, const Eigen::VectorXd& mu,
                               bool coulomb = false) {
  const Eigen::VectorXd u = n * gamma + r;
  double sum = 0.0;
  for (Eigen::Index i = 0; i < mu.size(); ++i) {
    const double step = 3.0 / n.block<3, 3>(3 * i, 3 * i).trace();
    const Eigen::Vector3d g = gamma.segment<3>(3 * i);
    Eigen::Vector3d ui = u.segment<3>(3 * i);
    if (coulomb) ui(0) += mu(i) * std::hypot(ui(1), ui(2));
    sum += ((g - referenceConeProjection(g - step * ui, mu(i))) / step).squaredNorm();
  }
  if (sum == 0.0) return 0.0;
  return std::sqrt(sum) / std::max(r.norm(), (u - r).norm());
}

/// Natural map residual of the true Coulomb law: as naturalMapResidual with u_n replaced by
/// De Saxce's u_n + mu ||u_t||.
inline double coulombResidual(const Eigen::VectorXd& gamma, const Eigen::VectorXd& u,
                              const Eigen::VectorXd& mu, const Eigen::VectorXd& r) {
  Eigen::VectorXd modified = u;
  for (Eigen::Index i = 0; i < mu.size(); ++i) {
    modified(3 * i) += mu(i) * std::hypot(u(3 * i + 1), u(3 * i + 2));
  }
  return naturalMap(gamma, modified, mu) / (1.0 + r.norm());
}

/// Error bound of the natural map for a symmetric positive definite N with eigenvalues in
/// [low, high]: the distance from gamma to the (unique) solution is at most
/// (1 + ||I - N|| / low) ||e||, e the unscaled natural map of gamma.
///
/// Derivation: p = gamma - e = Pi_K(gamma - u) gives <u - e, x* - p> >= 0, the solution x* gives
/// <u*, p - x*> >= 0; adding, with u - u* = N (p - x*) + N e:
/// low ||p - x*||^2 <= <(I - N) e, p - x*>, so ||p - x*|| <= ||I - N|| ||e|| / low, and
/// ||gamma - x*|| <= ||p - x*|| + ||e||.
inline double solutionDistanceBound(double low, double high, double natural_map) {
  const double identity_gap = std::max(std::abs(1.0 - low), std::abs(1.0 - high));
  return (1.0 + identity_gap / low) * natural_map;
}

/// Largest violation of gamma in K: max_i (||gamma_t,i|| - mu_i gamma_n,i), <= 0 when inside.
inline double coneViolation(const Eigen::VectorXd& gamma, const Eigen::VectorXd& mu) {
  double worst = -std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < mu.size(); ++i) {
    const double tangential = std::hypot(gamma(3 * i + 1), gamma(3 * i + 2));
    worst = std::max(worst, tangential - mu(i) * gamma(3 * i));
  }
  return worst;
}

/// A random symmetric positive definite n x n matrix with eigenvalues in [low, high].
inline Eigen::MatrixXd randomSpd(Eigen::Index n, double low, double high, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(low, high);
  Eigen::MatrixXd a(n, n);
  for (Eigen::Index i = 0; i < a.size(); ++i) a.data()[i] = normal(rng);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(a);
  const Eigen::MatrixXd q = qr.householderQ();
  Eigen::VectorXd eigenvalues(n);
  for (Eigen::Index i = 0; i < n; ++i) eigenvalues(i) = uniform(rng);
  return q * eigenvalues.asDiagonal() * q.transpose();
}

/// A random rows x cols matrix with standard normal entries.
inline Eigen::MatrixXd randomMatrix(Eigen::Index rows, Eigen::Index cols, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = normal(rng);
  return m;
}

/// A random vector with standard normal entries times `scale`.
inline Eigen::VectorXd randomVector(Eigen::Index n, double scale, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, scale);
  Eigen::VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v(i) = normal(rng);
  return v;
}

}  // namespace rheofeed::ccp::test
