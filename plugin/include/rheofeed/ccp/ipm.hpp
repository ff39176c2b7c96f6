// SPDX-License-Identifier: MIT
#pragma once

/// @file
/// Primal-dual interior-point method (IPM) for the convex cone problem of problem.hpp, and De
/// Saxce's fixed point around it for the true Coulomb law.
///
/// Convex problem: `min 1/2 gamma^T N gamma + (r + s e_n)^T gamma` over the friction cones K,
/// where `s` (nc, m/s) is a frozen normal offset per contact: s = 0 is the relaxed CCP of
/// problem.hpp, `s_i = mu_i ||u_t,i||` at the solution is the true Coulomb law (De Saxce's
/// modified velocity). Unlike the first-order solvers, an IPM's iteration count does not depend
/// on the conditioning of N: the crowded problems of the reference world (a rigid Delassus
/// operator plus the compliance cfm / h, condition numbers of 1e7) are solved to 1e-8 in 13-27
/// iterations (demos/results/coulomb_stall_probe_trough.md). In double precision the method
/// stalls near 1e-9 (the relative residual of ccp/solver.hpp).
///
/// Method (ours; after the cone QP solver of CVXOPT, Vandenberghe 2010): variables
/// `x_i = (mu_i gamma_n, gamma_t)` in the Lorentz cone, Nesterov-Todd scaling, Mehrotra's
/// predictor-corrector, the Newton system solved by a dense Cholesky factorisation (dense N) or,
/// matrix-free, as the sparse quasi-definite system `[Q, B^T; B, -I]` with `B = L^T D S`,
/// `M^-1 = L L^T` (its size is the generalised velocities plus the contact rows; no N is formed),
/// with one step of iterative refinement against N itself.
///
/// True Coulomb (IpmSolver::solve): the fixed point `s <- mu ||u_t(gamma(s))||` with the IPM
/// solving each convex problem to a share of the tolerance, warm started from the previous
/// outer iterate; the outer iterate with the lowest Coulomb residual is returned. The fixed
/// point converges on some crowded problems where NSGS stalls, and creeps where a sliding
/// contact's normal velocity is held away from zero by the others (its shift then moves by that
/// velocity in every outer iteration); the reference world alternates it with NSGS
/// (reference::Settings::ipm_rounds). See demos/bench/coulomb_stall_probe.cpp.
///
/// Contacts with mu = 0 are not supported (Status::InvalidInput naming the contact).
/// Residuals are those of solver.hpp (Result::residual, Result::coulomb_distance).

#include "rheofeed/ccp/problem.hpp"
#include "rheofeed/ccp/settings.hpp"

#include <Eigen/Core>

#include <memory>
#include <string>

namespace rheofeed::ccp {

/// Interior-point solver. Allocates in every solve. Not thread safe. Never throws for bad input
/// (Status::InvalidInput).
class IpmSolver {
 public:
  IpmSolver();
  explicit IpmSolver(const IpmSettings& settings);
  ~IpmSolver();
  IpmSolver(IpmSolver&&) noexcept;
  IpmSolver& operator=(IpmSolver&&) noexcept;
  IpmSolver(const IpmSolver&) = delete;
  IpmSolver& operator=(const IpmSolver&) = delete;

  const IpmSettings& settings() const { return settings_; }
  IpmSettings& settings() { return settings_; }

  /// True Coulomb law by De Saxce's fixed point with the IPM inside. `gamma` (3 nc, N s): the
  /// warm start's velocities give the first shift (IpmSettings::warm_start); on output the outer
  /// iterate with the lowest Coulomb residual (Converged when it meets the tolerance, else
  /// MaxIterations), in K. Result::iterations counts IPM iterations over all outer iterations,
  /// Result::outer_iterations the convex solves.
  Result solve(const Problem& problem, Eigen::VectorXd& gamma);

  /// The convex problem with the frozen normal offsets `shift` (nc, m/s, finite, >= 0; zeros:
  /// the relaxed CCP). `gamma` is output only. Result::residual is the convex problem's own
  /// natural-map residual (the shift in place of De Saxce's term); Converged when it is at or
  /// below IpmSettings::tolerance.
  Result solveConvex(const Problem& problem, const Eigen::VectorXd& shift, Eigen::VectorXd& gamma);

 private:
  struct Workspace;
  friend struct IpmRun;
  IpmSettings settings_;
  std::unique_ptr<Workspace> workspace_;
};

}  // namespace rheofeed::ccp
