// SPDX-License-Identifier: MIT
#pragma once

// The global nonsmooth Newton steps of NSGS (global_newton.cpp; internal to the cone solver
// library, used by nsgs.cpp; not installed).

#include "rheofeed/ccp/problem.hpp"
#include "solver_internal.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace rheofeed::ccp::detail {

/// Reusable storage of globalNewton().
struct GlobalNewtonWorkspace {
  /// Dense problems: the Delassus matrix N as a sparse matrix (1/kg), built by prepare().
  SparseMatrix n;
  /// Matrix-free problems: M^-1 D (ndof x 3 nc), built by prepare(); N is never formed (its
  /// pattern couples every pair of contacts on one body and fills in under factorisation).
  SparseMatrix minv_d;
  /// Alart-Curnier parameters of each contact (kg): 1 / W_nn and 1 / lambda_max(W_tt).
  Eigen::VectorXd rho_n, rho_t;
  bool prepared = false;
  /// Builds `n` or `minv_d` and the parameters from the problem (once per solve).
  void prepare(const Problem& problem);
  /// out = N g (3 nc, m/s) for impulses g (3 nc, N s), after prepare(). Not multiplyDelassus:
  /// that uses the solver workspace's generalised-velocity scratch, which NSGS keeps between
  /// sweeps.
  void multiplyN(const Problem& problem, const Eigen::VectorXd& g, Eigen::VectorXd& out) const;
};

/// Up to `iterations` semismooth Newton steps on the Alart-Curnier function of all contacts at
/// once, from `gamma` (3 nc, N s): each step solves the sparse linear system of the generalised
/// Jacobian J = B + A N by a sparse LU factorisation (matrix-free problems: of the augmented
/// system [B, A D^T; -M^-1 D, I] in (d gamma, M^-1 D d gamma), whose pattern is that of D rather
/// than N's); its length is limited to `step_limit`
/// (dimensionless, > 0) times the largest impulse of the iterate. Each iterate is projected
/// onto the cones and judged by its Coulomb residual (relativeResidual with `rho`, using
/// `base`'s contact scales); the steps stop early once one is at or below `tolerance`, or when
/// the deadline has expired. The best
/// one is written to `candidate` and its residual returned when it is lower than gamma's, else
/// -1 (candidate unspecified): a singular J, or no improvement.
double globalNewton(const Problem& problem, const Eigen::VectorXd& gamma, int iterations,
                    double step_limit, double tolerance, double rho, const Deadline& deadline,
                    GlobalNewtonWorkspace& ws, Workspace& base, Eigen::VectorXd& candidate);

}  // namespace rheofeed::ccp::detail
