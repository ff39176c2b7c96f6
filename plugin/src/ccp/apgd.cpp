// SPDX-License-Identifier: MIT
//
// APGD: accelerated projected gradient descent for the cone complementarity problem, after
// Mazhar, Heyn, Negrut & Tasora, "Using Nesterov's method to accelerate multibody dynamics with
// friction and contact", ACM Trans. Graph. 34(3), 2015 (their Algorithm APGD), implemented from
// the algorithm as published.
//
// The CCP is the optimality system of   min_{gamma in K} f(gamma) = 1/2 gamma^T N gamma + r^T
// gamma,  whose gradient is  grad f(y) = N y + r  (the full affine gradient, everywhere: using
// N y alone would solve a different problem). One iteration, with step t = 1/L:
//
//   gamma_{k+1} = Pi_K(y_k - t grad f(y_k))
//   while f(gamma_{k+1}) > f(y_k) + grad f(y_k)^T d + L/2 ||d||^2,  d = gamma_{k+1} - y_k:
//       L <- 2 L, recompute gamma_{k+1}                                  (Lipschitz backtracking)
//   theta_{k+1} = (-theta_k^2 + theta_k sqrt(theta_k^2 + 4)) / 2
//   beta_{k+1}  = theta_k (1 - theta_k) / (theta_k^2 + theta_{k+1})
//   y_{k+1}     = gamma_{k+1} + beta_{k+1} (gamma_{k+1} - gamma_k)                  (Nesterov)
//   if grad f(y_k)^T (gamma_{k+1} - gamma_k) > 0:  y_{k+1} = gamma_{k+1}, theta_{k+1} = 1
//                                                                       (gradient restart)
//   L <- 0.9 L                                     (let the step grow again)
//   keep the iterate with the smallest residual and return it.
//
// Implementation choices (not changing the algorithm):
// - f is quadratic, so the backtracking test is evaluated in the exact form
//   d^T N d <= L ||d||^2, with N d = N gamma_{k+1} - N y_k. Evaluating it as a difference of
//   objective values loses about half the digits near convergence (f ~ ||N|| ||gamma||^2 while
//   the terms compared shrink like ||d||^2) and stalls the method near 1e-8; a slack of a few
//   ulps of the products covers the remaining rounding.
// - N y_{k+1} is the same linear combination of N gamma_{k+1} and N gamma_k as y_{k+1}, so one
//   product with N per iteration suffices (plus one per backtracking step). N gamma is always a
//   fresh product, so no round-off accumulates.
// - The residual used to pick the best iterate is the natural map of solver.hpp, computed from
//   the fresh N gamma_{k+1}, so the returned residual is exact for the returned iterate.
// - Initial L: ||N e|| / ||e|| with e the vector of ones (the paper uses the secant between the
//   initial guess and a vector of ones); too small is corrected by backtracking.

#include "rheofeed/ccp/cone.hpp"
#include "solver_internal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rheofeed::ccp::detail {

namespace {

// Limits the doublings of L in one iteration: 2^kMaxBacktracks times the current estimate is
// beyond any finite Lipschitz constant the loop could need after a sane start.
constexpr int kMaxBacktracks = 200;
// Relative slack of the backtracking test for the rounding of N gamma_{k+1} - N y_k.
constexpr double kBacktrackSlack = 16.0 * std::numeric_limits<double>::epsilon();
// Per-iteration decrease of the Lipschitz estimate (paper: 0.9).
constexpr double kLipschitzDecrease = 0.9;

// Lipschitz estimate of N from the ones vector (ws.y, ws.n_y used as scratch); the largest
// mean block eigenvalue when that product is zero or not finite.
double initialLipschitz(const Problem& problem, Workspace& ws) {
  Eigen::VectorXd& y = ws.y;
  Eigen::VectorXd& n_y = ws.n_y;
  y.setOnes();
  multiplyDelassus(problem, y, n_y, ws);
  double lipschitz = safeNorm(n_y) / std::sqrt(double(y.size()));
  if (!(lipschitz > 0.0) || !std::isfinite(lipschitz)) {
    lipschitz = 0.0;
    for (Eigen::Index i = 0; i < problem.numContacts(); ++i) {
      lipschitz = std::max(lipschitz, problem.diagonalBlock(i).trace() / 3.0);
    }
  }
  return lipschitz;
}

// Projected gradient step from ws.y into ws.next (ws.n_next = N next) with backtracking on L
// (doubled until the quadratic model holds). False when the backtracking did not terminate.
bool projectedStep(const Problem& problem, const Eigen::VectorXd& r, const Eigen::VectorXd& mu,
                   Workspace& ws, double& lipschitz) {
  const Eigen::VectorXd& y = ws.y;
  const Eigen::VectorXd& n_y = ws.n_y;
  Eigen::VectorXd& next = ws.next;
  Eigen::VectorXd& n_next = ws.n_next;
  for (int backtrack = 0; backtrack <= kMaxBacktracks; ++backtrack) {
    const double step = 1.0 / lipschitz;
    for (Eigen::Index i = 0; i < problem.numContacts(); ++i) {
      const Eigen::Vector3d trial =
          y.segment<3>(3 * i) - step * (n_y.segment<3>(3 * i) + r.segment<3>(3 * i));
      next.segment<3>(3 * i) = projectOntoCone(trial, mu[i]);
    }
    multiplyDelassus(problem, next, n_next, ws);
    // d^T N d <= L ||d||^2 with d = next - y, N d = n_next - n_y, both sides divided by
    // max|d_i|^2 so that neither overflows nor underflows on data far from 1.
    const double d_max = (next - y).cwiseAbs().maxCoeff();
    if (d_max == 0.0) return true;  // y is a fixed point of the projected step
    const double curvature = ((next - y) / d_max).dot((n_next - n_y) / d_max);
    const double squared_step = ((next - y) / d_max).squaredNorm();
    const double slack =
        kBacktrackSlack * std::sqrt(squared_step) * (safeNorm(n_next) + safeNorm(n_y)) / d_max;
    if (curvature <= lipschitz * squared_step + slack) return true;
    lipschitz *= 2.0;
  }
  return false;
}

}  // namespace

InnerOutcome runApgd(const Problem& problem, const Eigen::VectorXd& r, const Eigen::VectorXd& mu,
                     const Settings& settings, const Deadline& deadline, Eigen::VectorXd& gamma,
                     Workspace& ws) {
  const double rho = settings.residual_rho;
  InnerOutcome out;

  Eigen::VectorXd& gk = ws.iterate;      // gamma_k
  Eigen::VectorXd& n_gk = ws.n_iterate;  // N gamma_k
  Eigen::VectorXd& next = ws.next;       // gamma_{k+1}
  Eigen::VectorXd& n_next = ws.n_next;   // N gamma_{k+1}
  Eigen::VectorXd& y = ws.y;
  Eigen::VectorXd& n_y = ws.n_y;

  double lipschitz = initialLipschitz(problem, ws);

  gk = gamma;
  multiplyDelassus(problem, gk, n_gk, ws);
  ws.u = n_gk + r;
  double best_residual = relativeResidual(gk, ws.u, r, mu, rho, false, ws);
  ws.best = gk;
  out.residual = best_residual;
  if (!std::isfinite(best_residual)) {
    out.status = Status::NumericalIssue;
    out.issue = "APGD: non-finite residual at the initial guess";
    gamma.setZero();
    return out;
  }
  if (best_residual <= settings.tolerance) {
    out.status = Status::Converged;
    return out;
  }

  y = gk;
  n_y = n_gk;
  double theta = 1.0;
  out.status = Status::MaxIterations;
  for (int k = 1; k <= settings.max_iterations; ++k) {
    out.iterations = k;
    const bool accepted = projectedStep(problem, r, mu, ws, lipschitz);
    if (!accepted || !std::isfinite(lipschitz)) {
      out.status = Status::NumericalIssue;
      out.issue = "APGD: Lipschitz backtracking did not terminate";
      break;
    }

    // Residual of the new iterate, from the fresh product N gamma_{k+1}.
    ws.u = n_next + r;
    const double residual = relativeResidual(next, ws.u, r, mu, rho, false, ws);
    if (!std::isfinite(residual)) {
      out.status = Status::NumericalIssue;
      out.issue = "APGD: non-finite residual (impulses or velocities overflowed)";
      break;
    }
    if (residual < best_residual) {
      best_residual = residual;
      ws.best = next;
    }
    if (residual <= settings.tolerance) {
      out.status = Status::Converged;
      break;
    }

    // Gradient restart test: grad f(y_k)^T (gamma_{k+1} - gamma_k) > 0, each factor divided by
    // its largest entry (the sign is all that matters; the product could overflow).
    const double gradient_max = (n_y + r).cwiseAbs().maxCoeff();
    const double move_max = (next - gk).cwiseAbs().maxCoeff();
    const bool restart = gradient_max > 0.0 && move_max > 0.0 &&
                         ((n_y + r) / gradient_max).dot((next - gk) / move_max) > 0.0;
    const double theta_next = 0.5 * (-theta * theta + theta * std::sqrt(theta * theta + 4.0));
    if (restart) {
      y = next;
      n_y = n_next;
      theta = 1.0;
    } else {
      const double beta = theta * (1.0 - theta) / (theta * theta + theta_next);
      y = (1.0 + beta) * next - beta * gk;
      n_y = (1.0 + beta) * n_next - beta * n_gk;
      theta = theta_next;
    }
    gk.swap(next);
    n_gk.swap(n_next);
    lipschitz *= kLipschitzDecrease;

    if (deadline.expired()) {
      out.timed_out = true;
      break;
    }
  }
  gamma = ws.best;
  out.residual = best_residual;
  return out;
}

}  // namespace rheofeed::ccp::detail
