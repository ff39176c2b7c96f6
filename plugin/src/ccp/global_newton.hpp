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
  /// The Delassus matrix N as a sparse matrix (1/kg), built by prepare().
  SparseMatrix n;
  /// Alart-Curnier parameters of each contact (kg): 1 / W_nn and 1 / lambda_max(W_tt).
  Eigen::VectorXd rho_n, rho_t;
  bool prepared = false;
  /// Builds `n` and the parameters from the problem (once per solve).
  void prepare(const Problem& problem);
};

/// Up to `iterations` semismooth Newton steps on the Alart-Curnier function of all contacts at
/// once, from `gamma` (3 nc, N s): each step solves the sparse linear system of the generalised
/// Jacobian J = B + A N by a sparse LU factorisation; its length is limited to `step_limit`
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
