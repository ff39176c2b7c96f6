// SPDX-License-Identifier: MIT
#pragma once

// Helpers shared by the CCP tests. They are deliberately independent of the code under test:
// the cone projection here is the textbook formula, and residuals are recomputed from the
// returned impulses with the test's own products.

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/QR>
#include "rheofeed/ccp/problem.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <vector>

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

/// The Siconos fc3d problems of tests/data/fc3d every Coulomb solver's test runs.
inline const char* const kFc3dFiles[] = {"FrictionContact3D_1c.dat",
                                         "FC3D_Example1.dat",
                                         "Rover4396.dat",
                                         "Rover1039.dat",
                                         "Rover3865.dat",
                                         "NESpheres_10_1.dat",
                                         "BoxesStack1-i100000-32.hdf5.dat",
                                         "Capsules-i101-404.dat"};

/// A test name from an fc3d file name (non-alphanumerics become '_').
inline std::string fc3dTestName(const testing::TestParamInfo<const char*>& param_info) {
  std::string name = param_info.param;
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

/// "Dense" or "MatrixFree" for a test parameterised on the matrix-free form.
inline std::string formName(const testing::TestParamInfo<bool>& param_info) {
  return param_info.param ? "MatrixFree" : "Dense";
}

/// One step of a point mass `mass` (kg) at rest on an incline of angle `theta` (rad) with
/// friction `mu`, step `h` (s), gravity 9.81 m/s^2 (contact frame: n out of the plane, t1 down
/// the slope, t2 across): r = h g (-cos theta, sin theta, 0), N = I / m, dense or matrix-free.
inline Problem inclineStep(double mass, double theta, double mu, double h, bool matrix_free) {
  const double g = 9.81;
  Eigen::VectorXd r(3);
  r << -h * g * std::cos(theta), h * g * std::sin(theta), 0.0;
  Eigen::VectorXd friction(1);
  friction << mu;
  if (!matrix_free) return Problem::makeDense(Eigen::Matrix3d::Identity() / mass, r, friction);
  SparseMatrix d(3, 3), minv(3, 3);
  d.setIdentity();
  minv.setIdentity();
  minv *= 1.0 / mass;
  return Problem::makeMatrixFree(d, minv, r, friction);
}

/// The incline step's closed form (inclineStep, gravity 9.81 m/s^2) checked on `gamma`: below
/// the friction angle the mass stays at rest and the impulses carry the weight's two components;
/// above it, it slides with no separation (true Coulomb, not the relaxation's mu |u_t|), friction
/// mu N against the slip and acceleration g (sin theta - mu cos theta). Absolute tolerances on
/// impulses (N s), velocities (m/s) and the acceleration (m/s^2).
inline void expectInclineLaw(const Problem& problem, const Eigen::VectorXd& gamma, double mass,
                             double theta, double mu, double h, double impulse_tol,
                             double velocity_tol, double acceleration_tol) {
  const double g = 9.81;
  const Eigen::VectorXd u = problem.contactVelocity(gamma);
  const double weight = mass * h * g;  // N s
  EXPECT_NEAR(gamma[0], weight * std::cos(theta), impulse_tol);
  if (std::tan(theta) <= mu) {
    EXPECT_NEAR(u.norm(), 0.0, velocity_tol);
    EXPECT_NEAR(gamma[1], -weight * std::sin(theta), impulse_tol);
    EXPECT_NEAR(gamma[2], 0.0, impulse_tol);
    return;
  }
  EXPECT_NEAR(u[0], 0.0, velocity_tol);
  EXPECT_NEAR(u[1] / h, g * (std::sin(theta) - mu * std::cos(theta)), acceleration_tol);
  EXPECT_NEAR(u[2], 0.0, velocity_tol);
  EXPECT_NEAR(gamma[1], -mu * gamma[0], impulse_tol);
}

/// A matrix-free problem with `nc` contacts on `bodies` bodies (6 dofs each), each contact
/// coupling two bodies through random rows of D (seeded with 7), M^-1 diagonal; with
/// `compliance` c > 0 (1/kg) the reference world's N + c I is built as it does
/// (reference/world_contacts.cpp): one virtual unit-mass coordinate per contact row with D entry
/// sqrt(c). Friction 0.3-0.45, r random in [-1, 1] m/s.
inline Problem coupledProblem(int bodies, int nc, double compliance) {
  const int rigid = 6 * bodies, rows = rigid + (compliance > 0.0 ? 3 * nc : 0);
  SparseMatrix d(rows, 3 * nc), minv(rows, rows);
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
  for (int k = rigid; k < rows; ++k) entries.emplace_back(k, k - rigid, std::sqrt(compliance));
  d.setFromTriplets(entries.begin(), entries.end());
  entries.clear();
  for (int q = 0; q < rigid; ++q) entries.emplace_back(q, q, 0.5 + 0.1 * (q % 5));
  for (int k = rigid; k < rows; ++k) entries.emplace_back(k, k, 1.0);
  minv.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd r(3 * nc), mu(nc);
  for (int i = 0; i < 3 * nc; ++i) r[i] = random();
  for (int i = 0; i < nc; ++i) mu[i] = 0.3 + 0.05 * (i % 4);
  return Problem::makeMatrixFree(d, minv, r, mu);
}

}  // namespace rheofeed::ccp::test
