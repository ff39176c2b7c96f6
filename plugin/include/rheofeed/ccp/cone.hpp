// SPDX-License-Identifier: MIT
#pragma once

/// @file
/// Euclidean projections onto the Coulomb friction cone of one contact, its polar and its dual.
///
/// A contact vector is `x = (n, t)` with `n = x[0]` the component along the contact normal and
/// `t = (x[1], x[2])` the two tangential components, in the contact frame (n, u, v). For impulses
/// the unit is N s, for velocities m/s; the projections are unit agnostic.
///
/// - Friction cone `K_mu = {(n, t) : ||t|| <= mu n}` (impulses live here).
/// - Dual cone `K_mu* = {(n, t) : mu ||t|| <= n}` (relaxed contact velocities live here).
/// - Polar cone `K_mu° = -K_mu* = {(n, t) : n + mu ||t|| <= 0}`.
///
/// Moreau's decomposition holds for every x: `x = Pi_K(x) + Pi_K°(x)` with both parts orthogonal.
/// The projection onto `K_mu` with `s = ||t||` is: keep x when `s <= mu n`; return 0 when
/// `mu s <= -n` (x is in the polar cone); otherwise project onto the boundary ray, which gives
/// `n' = (mu s + n) / (1 + mu^2)`, `t' = mu n' t / s`. Here the boundary ray is written with the
/// unit vector `(c, sigma t/s)`, `c = 1/sqrt(1 + mu^2)`, `sigma = mu/sqrt(1 + mu^2)`, evaluated so
/// that any finite `mu` (0 up to ~1e308) gives a finite result: `mu^2` is never formed.

#include <Eigen/Core>

#include <cmath>

namespace rheofeed::ccp {

namespace detail {

/// Unit vector of the friction cone's boundary ray in the (normal, tangential) half plane:
/// `cos_angle = 1/sqrt(1 + mu^2)`, `sin_angle = mu/sqrt(1 + mu^2)`, computed without forming
/// `mu^2` (no overflow for large finite mu). `mu` >= 0, dimensionless.
inline void coneRay(double mu, double& cos_angle, double& sin_angle) {
  if (mu <= 1.0) {
    cos_angle = 1.0 / std::sqrt(1.0 + mu * mu);
    sin_angle = mu * cos_angle;
  } else {
    const double k = 1.0 / mu;
    sin_angle = 1.0 / std::sqrt(1.0 + k * k);
    cos_angle = k * sin_angle;
  }
}

/// Norm of the tangential part `(x[1], x[2])`, without spurious underflow or overflow: the fast
/// formula is used in the range where squaring is exact enough, std::hypot outside it.
inline double tangentialNorm(const Eigen::Vector3d& x) {
  const double squared = x[1] * x[1] + x[2] * x[2];
  if (squared > 1e-300 && squared < 1e300) return std::sqrt(squared);
  if (x[1] == 0.0 && x[2] == 0.0) return 0.0;
  return std::hypot(x[1], x[2]);
}

}  // namespace detail

/// Euclidean projection of `x = (n, t)` onto the friction cone `K_mu = {||t|| <= mu n}`.
/// `mu` is the (dimensionless) friction coefficient, finite and >= 0; `mu = 0` gives
/// `(max(n, 0), 0, 0)`. Components are in the contact frame (normal first).
inline Eigen::Vector3d projectOntoCone(const Eigen::Vector3d& x, double mu) {
  const double n = x[0];
  if (mu == 0.0) return Eigen::Vector3d(n > 0.0 ? n : 0.0, 0.0, 0.0);  // the half line t = 0
  const double s = detail::tangentialNorm(x);
  if (s <= mu * n) return x;                         // inside K (includes s = 0, n >= 0)
  if (mu * s <= -n) return Eigen::Vector3d::Zero();  // inside the polar cone (includes s = 0)
  // Here s > 0: for mu > 0 the two tests above cover s = 0 for either sign of n.
  double c = 0.0, sigma = 0.0;
  detail::coneRay(mu, c, sigma);
  const double alpha = c * n + sigma * s;  // length of the projection on the boundary ray
  const double tangential_scale = alpha * sigma / s;
  return Eigen::Vector3d(alpha * c, tangential_scale * x[1], tangential_scale * x[2]);
}

/// Euclidean projection of `x = (n, t)` onto the polar cone `K_mu° = {n + mu ||t|| <= 0}`.
/// Computed directly (not as `x - Pi_K(x)`), so that Moreau's decomposition can be checked.
/// `mu` finite and >= 0 (dimensionless); for `mu = 0` the polar cone is the half space `n <= 0`.
inline Eigen::Vector3d projectOntoPolarCone(const Eigen::Vector3d& x, double mu) {
  const double n = x[0];
  if (mu == 0.0) return Eigen::Vector3d(n < 0.0 ? n : 0.0, x[1], x[2]);  // the half space n <= 0
  const double s = detail::tangentialNorm(x);
  if (mu * s <= -n) return x;                       // inside the polar cone
  if (s <= mu * n) return Eigen::Vector3d::Zero();  // inside K: nothing of x is polar
  double c = 0.0, sigma = 0.0;
  detail::coneRay(mu, c, sigma);
  // Boundary ray of the polar cone: unit vector (-sigma, c t/s), orthogonal to K's ray.
  const double beta = -sigma * n + c * s;
  const double tangential_scale = beta * c / s;
  return Eigen::Vector3d(-beta * sigma, tangential_scale * x[1], tangential_scale * x[2]);
}

/// Euclidean projection of `x = (n, t)` onto the dual cone `K_mu* = {mu ||t|| <= n}`, by Moreau's
/// decomposition applied to the dual pair: `Pi_K*(x) = x + Pi_K(-x)`. `mu` finite, >= 0; for
/// `mu = 0` the dual cone is the half space `n >= 0`.
inline Eigen::Vector3d projectOntoDualCone(const Eigen::Vector3d& x, double mu) {
  return x + projectOntoCone(-x, mu);
}

/// Euclidean distance from `x` to the dual cone `K_mu*`, equal to `||Pi_K(-x)||`. For a contact
/// velocity `u` (m/s) this is how far `u` is from satisfying the relaxed non-penetration and
/// friction law `u_n >= mu ||u_t||` (unit of x).
inline double distanceToDualCone(const Eigen::Vector3d& x, double mu) {
  return projectOntoCone(-x, mu).norm();
}

}  // namespace rheofeed::ccp
