// SPDX-License-Identifier: MIT
//
// The one-contact Coulomb problem of nonsmooth Gauss-Seidel (nsgs.cpp), after Alart & Curnier
// ("A mixed formulation for frictional contact problems prone to Newton like solution methods",
// CMAME 1991) and the local solvers compared by Acary, Bremond & Huber (INRIA RR-9118, 2018).
//
// Given the contact's Delassus block W (3 x 3, SPD) and the velocity q of everything else, find
// r in K_mu = {||r_t|| <= mu r_n} with u = W r + q obeying Coulomb's law: take-off (r = 0,
// u_n >= 0), stick (u = 0, r in K_mu) or slide (u_n = 0, r_t = -mu r_n u_t / ||u_t||).
//
// 1. Closed forms first. r = 0 is a solution exactly when q_n >= 0 (De Saxce's modified velocity
//    q + mu ||q_t|| e_n is in the dual cone iff q_n >= 0). Otherwise the sticking impulse
//    r = -W^-1 q is the solution when it lies in K_mu; with mu = 0 the normal impulse alone is.
// 2. Sliding: Newton's method on the Alart-Curnier function
//        Phi_n(r) = r_n - max(0, r_n - rho_n u_n)
//        Phi_t(r) = r_t - Pi_{D(mu max(0, r_n - rho_n u_n))}(r_t - rho_t u_t)
//    (Pi_D(R) the projection onto the disk of radius R), whose zeros are exactly the Coulomb
//    solutions. Phi is piecewise smooth; J is one element of its generalised Jacobian:
//        with a = r_n - rho_n u_n, b = r_t - rho_t u_t, R = mu max(a, 0),
//        dPhi_n = e_n^T - [a > 0] (e_n^T - rho_n W_n)
//        dPhi_t = [0 I] - db                          (||b|| <= R: the disk's interior)
//        dPhi_t = [0 I] - (b/|b|) mu [a > 0] (e_n^T - rho_n W_n)
//                       - (R/|b|) (I - b b^T/|b|^2) db   (||b|| > R), db = [0 I] - rho_t W_t.
//    The parameters are the block's own scales, rho_n = 1 / W_nn and rho_t = 1 / lambda_max(W_tt)
//    (kg): a fixed rho = 1 makes the Newton steps depend on the units and, per RR-9118, badly
//    hurts robustness. Each step is globalised by an Armijo line search on 1/2 ||Phi||^2 (the
//    Newton direction d solves J d = -Phi, so the merit's slope along d is -||Phi||^2).
// 3. Fallback when Newton stalls (singular J, a line search that fails, or the iteration budget):
//    the projection fixed point r <- Pi_K(r - s (W r + q + mu ||u_t|| e_n)) with local
//    iterations, its step s halved whenever the residual grows, keeping the best iterate.
//
// The local residual (localCoulombResidual) is the natural map of De Saxce's formulation, the
// same measure as the global stopping test of nsgs.cpp restricted to one contact.

#include "local_coulomb.hpp"

#include "rheofeed/ccp/cone.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rheofeed::ccp::detail {

namespace {

// Armijo's sufficient decrease on the merit 1/2 ||Phi||^2 and the line search's halvings.
constexpr double kArmijo = 1e-4;
constexpr int kMaxHalvings = 30;
// Levenberg-Marquardt fallback of the group Newton: first damping relative to the largest
// diagonal entry of J^T J, and the number of tenfold increases.
constexpr double kFirstDamping = 1e-8;
constexpr int kMaxDampings = 12;
// The projection fallback's step shrinks by this factor whenever its residual grows.
constexpr double kProjectionShrink = 0.5;

struct AlartCurnier {
  const Eigen::Matrix3d& w;
  const Eigen::Vector3d& q;
  double mu;
  double rho_n;
  double rho_t;

  // Phi(r); when `jacobian` is given, one element of its generalised Jacobian too.
  Eigen::Vector3d value(const Eigen::Vector3d& r, Eigen::Matrix3d* jacobian) const {
    const Eigen::Vector3d u = w * r + q;
    const double a = r[0] - rho_n * u[0];
    const double pn = a > 0.0 ? a : 0.0;
    const double radius = mu * pn;
    const Eigen::Vector2d b = r.tail<2>() - rho_t * u.tail<2>();
    const double nb = b.norm();
    const bool inside = nb <= radius;
    Eigen::Vector3d phi;
    phi[0] = r[0] - pn;
    phi.tail<2>() = r.tail<2>() - (inside ? b : Eigen::Vector2d(radius * b / nb));
    if (jacobian != nullptr) {
      Eigen::Matrix3d& j = *jacobian;
      Eigen::RowVector3d da = -rho_n * w.row(0);
      da[0] += 1.0;
      j.row(0) = Eigen::RowVector3d(1.0, 0.0, 0.0) - (a > 0.0 ? da : Eigen::RowVector3d::Zero());
      Eigen::Matrix<double, 2, 3> db = -rho_t * w.bottomRows<2>();
      db(0, 1) += 1.0;
      db(1, 2) += 1.0;
      Eigen::Matrix<double, 2, 3> dp;
      if (inside) {
        dp = db;
      } else {
        const Eigen::Vector2d unit = b / nb;
        const Eigen::Matrix2d tangent = Eigen::Matrix2d::Identity() - unit * unit.transpose();
        dp = (radius / nb) * tangent * db;
        if (a > 0.0) dp += mu * unit * da;
      }
      j.bottomRows<2>() = -dp;
      j(1, 1) += 1.0;
      j(2, 2) += 1.0;
    }
    return phi;
  }
};

// Backtracking line search along d from r on the merit 1/2 ||Phi||^2 (slope: its directional
// derivative along d, < 0): the first t = 1, 1/2, ... with Armijo's sufficient decrease.
template <class Function, class Vector>
bool armijoSearch(const Function& phi, const Vector& r, const Vector& d, double merit, double slope,
                  Vector& trial, double& trial_merit) {
  double t = 1.0;
  for (int halving = 0; halving < kMaxHalvings; ++halving, t *= 0.5) {
    trial = r + t * d;
    trial_merit = 0.5 * phi.value(trial, nullptr).squaredNorm();
    if (trial_merit <= merit + kArmijo * t * slope) return true;
  }
  return false;
}

// Largest eigenvalue of a symmetric 2 x 2 matrix.
double largestEigenvalue(const Eigen::Matrix2d& m) {
  const double mean = 0.5 * (m(0, 0) + m(1, 1));
  const double half_gap = 0.5 * (m(0, 0) - m(1, 1));
  return mean + std::sqrt(half_gap * half_gap + m(0, 1) * m(1, 0));
}

bool newton(const AlartCurnier& ac, const LocalSettings& settings, Eigen::Vector3d& r) {
  Eigen::Matrix3d jacobian;
  Eigen::Vector3d phi = ac.value(r, &jacobian);
  double merit = 0.5 * phi.squaredNorm();
  for (int k = 0; k < settings.max_newton_iterations; ++k) {
    // Converged (also at the start: a warm start from the last sweep often is the solution).
    const Eigen::Vector3d projected = projectOntoCone(r, ac.mu);
    if (localCoulombResidual(ac.w, ac.q, ac.mu, projected) <= settings.tolerance) {
      r = projected;
      return true;
    }
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(jacobian);
    if (!lu.isInvertible()) return false;
    const Eigen::Vector3d d = lu.solve(-phi);
    if (!d.allFinite()) return false;
    Eigen::Vector3d trial;
    double trial_merit = merit;
    // The Newton direction's slope of the merit is -||Phi||^2 = -2 merit.
    if (!armijoSearch(ac, r, d, merit, -2.0 * merit, trial, trial_merit)) return false;
    r = trial;
    phi = ac.value(r, &jacobian);
    merit = trial_merit;
  }
  const Eigen::Vector3d projected = projectOntoCone(r, ac.mu);
  if (localCoulombResidual(ac.w, ac.q, ac.mu, projected) <= settings.tolerance) {
    r = projected;
    return true;
  }
  return false;
}

// Projection fixed point on De Saxce's modified velocity with local iterations and a step that
// halves when the residual grows. Returns true when the best iterate meets the tolerance.
bool projection(const Eigen::Matrix3d& w, const Eigen::Vector3d& q, double mu,
                const LocalSettings& settings, double step, Eigen::Vector3d& r) {
  Eigen::Vector3d best = projectOntoCone(r, mu);
  double best_residual = localCoulombResidual(w, q, mu, best);
  Eigen::Vector3d x = best;
  double last = best_residual;
  for (int k = 0; k < settings.max_projection_iterations && best_residual > settings.tolerance;
       ++k) {
    Eigen::Vector3d u = w * x + q;
    u[0] += mu * u.tail<2>().norm();
    x = projectOntoCone(x - step * u, mu);
    const double residual = localCoulombResidual(w, q, mu, x);
    if (residual < best_residual) {
      best_residual = residual;
      best = x;
    }
    if (residual > last) step *= kProjectionShrink;
    last = residual;
  }
  r = best;
  return best_residual <= settings.tolerance;
}

}  // namespace

double localCoulombResidual(const Eigen::Matrix3d& w, const Eigen::Vector3d& q, double mu,
                            const Eigen::Vector3d& r) {
  const Eigen::Vector3d wr = w * r;
  Eigen::Vector3d u = wr + q;
  u[0] += mu * std::hypot(u[1], u[2]);
  const double step = 3.0 / w.trace();
  const double error = ((r - projectOntoCone(r - step * u, mu)) / step).norm();
  const double scale = std::max(q.norm(), wr.norm());
  if (error == 0.0) return 0.0;
  return scale > 0.0 ? error / scale : std::numeric_limits<double>::infinity();
}

LocalOutcome solveLocalCoulomb(const Eigen::Matrix3d& w, const Eigen::Vector3d& q, double mu,
                               const LocalSettings& settings, Eigen::Vector3d& r) {
  if (q[0] >= 0.0) {
    r.setZero();
    return LocalOutcome::TakeOff;
  }
  if (mu == 0.0) {
    // Frictionless: the normal row alone, u_n = W_nn r_n + q_n = 0.
    r = Eigen::Vector3d(-q[0] / w(0, 0), 0.0, 0.0);
    return LocalOutcome::Stick;
  }
  const Eigen::Vector3d stick = -w.inverse() * q;
  if (stick[0] > 0.0 && stick.tail<2>().norm() <= mu * stick[0] && stick.allFinite()) {
    r = stick;
    return LocalOutcome::Stick;
  }
  // Sliding. Start from the incoming impulse when it presses, else from the sticking impulse
  // projected onto the cone, else from the frictionless normal impulse.
  Eigen::Vector3d start = projectOntoCone(r, mu);
  if (!(start[0] > 0.0) || !start.allFinite()) start = projectOntoCone(stick, mu);
  if (!(start[0] > 0.0) || !start.allFinite()) start = Eigen::Vector3d(-q[0] / w(0, 0), 0, 0);
  const double rho_t = 1.0 / largestEigenvalue(w.bottomRightCorner<2, 2>());
  const AlartCurnier ac{w, q, mu, 1.0 / w(0, 0), rho_t};
  Eigen::Vector3d x = start;
  if (newton(ac, settings, x)) {
    r = x;
    return LocalOutcome::Newton;
  }
  // The projection's step: the inverse of the block's largest eigenvalue (a descent step).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(0.5 * (w + w.transpose()),
                                                             Eigen::EigenvaluesOnly);
  Eigen::Vector3d y =
      localCoulombResidual(w, q, mu, projectOntoCone(x, mu)) < localCoulombResidual(w, q, mu, start)
          ? x
          : start;
  const bool converged = projection(w, q, mu, settings, 1.0 / eigen.eigenvalues()[2], y);
  r = y;
  return converged ? LocalOutcome::Projection : LocalOutcome::Unconverged;
}

}  // namespace rheofeed::ccp::detail

namespace rheofeed::ccp::detail {

namespace {

// The group's Alart-Curnier function, contact by contact as AlartCurnier::value, with the rows
// of the coupled block W.
struct GroupAlartCurnier {
  const GroupMatrix& w;
  const GroupVector& q;
  const GroupVector& mu;
  GroupVector rho_n, rho_t;

  GroupAlartCurnier(const GroupMatrix& w_in, const GroupVector& q_in, const GroupVector& mu_in)
      : w(w_in), q(q_in), mu(mu_in) {
    const Eigen::Index k = mu.size();
    rho_n.resize(k);
    rho_t.resize(k);
    for (Eigen::Index a = 0; a < k; ++a) {
      rho_n[a] = 1.0 / w(3 * a, 3 * a);
      rho_t[a] = 1.0 / largestEigenvalue(w.block<2, 2>(3 * a + 1, 3 * a + 1));
    }
  }

  GroupVector value(const GroupVector& r, GroupMatrix* jacobian) const {
    const Eigen::Index k = mu.size(), n = 3 * k;
    const GroupVector u = w * r + q;
    GroupVector phi(n);
    if (jacobian != nullptr) jacobian->setZero(n, n);
    for (Eigen::Index c = 0; c < k; ++c) {
      const Eigen::Index i = 3 * c;
      const double a = r[i] - rho_n[c] * u[i];
      const double pn = a > 0.0 ? a : 0.0;
      const double radius = mu[c] * pn;
      const Eigen::Vector2d b = r.segment<2>(i + 1) - rho_t[c] * u.segment<2>(i + 1);
      const double nb = b.norm();
      const bool inside = nb <= radius;
      phi[i] = r[i] - pn;
      phi.segment<2>(i + 1) = r.segment<2>(i + 1) - (inside ? b : Eigen::Vector2d(radius * b / nb));
      if (jacobian == nullptr) continue;
      GroupMatrix& j = *jacobian;
      // da = e_i^T - rho_n W_i; row i of J = e_i^T - [a > 0] da.
      if (a > 0.0)
        j.row(i) = rho_n[c] * w.row(i);
      else
        j(i, i) = 1.0;
      // db = E_t^T - rho_t W_t; rows of J = E_t^T - dp.
      Eigen::Matrix<double, 2, Eigen::Dynamic, 0, 2, 3 * kMaxGroupContacts> db =
          -rho_t[c] * w.middleRows<2>(i + 1);
      db(0, i + 1) += 1.0;
      db(1, i + 2) += 1.0;
      Eigen::Matrix<double, 2, Eigen::Dynamic, 0, 2, 3 * kMaxGroupContacts> dp(2, n);
      if (inside) {
        dp = db;
      } else {
        const Eigen::Vector2d unit = b / nb;
        const Eigen::Matrix2d tangent = Eigen::Matrix2d::Identity() - unit * unit.transpose();
        dp = (radius / nb) * tangent * db;
        if (a > 0.0) {
          Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, 3 * kMaxGroupContacts> da =
              -rho_n[c] * w.row(i);
          da[i] += 1.0;
          dp += mu[c] * unit * da;
        }
      }
      j.middleRows<2>(i + 1) = -dp;
      j(i + 1, i + 1) += 1.0;
      j(i + 2, i + 2) += 1.0;
    }
    return phi;
  }
};

// The group's residual: the natural map of De Saxce's velocity contact by contact (step
// 3 / trace(W_cc)), relative to max(||q||, ||W r||).
double groupResidual(const GroupMatrix& w, const GroupVector& q, const GroupVector& mu,
                     const GroupVector& r) {
  const GroupVector wr = w * r;
  const GroupVector u = wr + q;
  double error = 0.0;
  for (Eigen::Index c = 0; c < mu.size(); ++c) {
    Eigen::Vector3d v = u.segment<3>(3 * c);
    v[0] += mu[c] * std::hypot(v[1], v[2]);
    const double step = 3.0 / w.block<3, 3>(3 * c, 3 * c).trace();
    const Eigen::Vector3d g = r.segment<3>(3 * c);
    error += ((g - projectOntoCone(g - step * v, mu[c])) / step).squaredNorm();
  }
  const double scale = std::max(q.norm(), wr.norm());
  if (error == 0.0) return 0.0;
  return scale > 0.0 ? std::sqrt(error) / scale : std::numeric_limits<double>::infinity();
}

void projectGroup(GroupVector& r, const GroupVector& mu) {
  for (Eigen::Index c = 0; c < mu.size(); ++c) {
    r.segment<3>(3 * c) = projectOntoCone(r.segment<3>(3 * c), mu[c]);
  }
}

bool groupNewton(const GroupAlartCurnier& ac, const LocalSettings& settings, GroupVector& r) {
  GroupMatrix jacobian;
  GroupVector phi = ac.value(r, &jacobian);
  double merit = 0.5 * phi.squaredNorm();
  for (int k = 0; k <= settings.max_newton_iterations; ++k) {
    GroupVector projected = r;
    projectGroup(projected, ac.mu);
    if (groupResidual(ac.w, ac.q, ac.mu, projected) <= settings.tolerance) {
      r = projected;
      return true;
    }
    if (k == settings.max_newton_iterations) break;
    // The Newton direction first; when its line search fails (near-singular J: the block is
    // rank deficient up to the compliance, and the merit has kinks), Levenberg-Marquardt
    // directions (J^T J + lambda I) d = -J^T Phi with lambda growing tenfold, which turn towards
    // the merit's steepest descent -J^T Phi.
    const GroupVector gradient = jacobian.transpose() * phi;
    const GroupMatrix normal = jacobian.transpose() * jacobian;
    double lambda = 0.0;
    bool accepted = false;
    GroupVector trial;
    double trial_merit = merit;
    for (int attempt = 0; attempt <= kMaxDampings && !accepted; ++attempt) {
      GroupVector d;
      if (attempt == 0) {
        const Eigen::FullPivLU<GroupMatrix> lu(jacobian);
        if (!lu.isInvertible()) continue;
        d = lu.solve(-phi);
      } else {
        lambda = lambda == 0.0 ? kFirstDamping * normal.diagonal().maxCoeff() : 10.0 * lambda;
        GroupMatrix damped = normal;
        damped.diagonal().array() += lambda;
        d = damped.ldlt().solve(-gradient);
      }
      if (!d.allFinite()) continue;
      // Armijo on the merit with its slope gradient . d along d.
      const double slope = gradient.dot(d);
      if (!(slope < 0.0)) continue;
      accepted = armijoSearch(ac, r, d, merit, slope, trial, trial_merit);
    }
    if (!accepted) return false;
    r = trial;
    phi = ac.value(r, &jacobian);
    merit = trial_merit;
  }
  return false;
}

}  // namespace

LocalOutcome solveGroupCoulomb(const GroupMatrix& w, const GroupVector& q, const GroupVector& mu,
                               const LocalSettings& settings, GroupVector& r) {
  const Eigen::Index k = mu.size();
  projectGroup(r, mu);
  const GroupAlartCurnier ac(w, q, mu);
  GroupVector x = r;
  if (groupNewton(ac, settings, x)) {
    r = x;
    return LocalOutcome::Newton;
  }
  // Fallback: passes of exact one-contact solves over the group from the better of the start
  // and Newton's last iterate, keeping the best.
  projectGroup(x, mu);
  double best_residual = groupResidual(w, q, mu, r);
  GroupVector best = r;
  if (const double newton_residual = groupResidual(w, q, mu, x); newton_residual < best_residual) {
    best_residual = newton_residual;
    best = x;
  }
  x = best;
  for (int pass = 0; pass < settings.max_projection_iterations; ++pass) {
    for (Eigen::Index c = 0; c < k; ++c) {
      const Eigen::Matrix3d wc = w.block<3, 3>(3 * c, 3 * c);
      const Eigen::Vector3d qc =
          (w.middleRows<3>(3 * c) * x).eval() + q.segment<3>(3 * c) - wc * x.segment<3>(3 * c);
      Eigen::Vector3d rc = x.segment<3>(3 * c);
      solveLocalCoulomb(wc, qc, mu[c], settings, rc);
      x.segment<3>(3 * c) = rc;
    }
    const double residual = groupResidual(w, q, mu, x);
    if (residual < best_residual) {
      best_residual = residual;
      best = x;
    }
    if (best_residual <= settings.tolerance) break;
  }
  r = best;
  return best_residual <= settings.tolerance ? LocalOutcome::Projection : LocalOutcome::Unconverged;
}

}  // namespace rheofeed::ccp::detail
