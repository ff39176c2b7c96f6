// SPDX-License-Identifier: MIT
#pragma once

// The Coulomb residual of ccp/solver.hpp computed independently of the solvers, for the
// benchmarks that judge them (ccp_solver_comparison, coulomb_stall_probe).

#include <Eigen/Core>

#include "rheofeed/ccp/problem.hpp"

namespace rheofeed::bench {

// Dimensionless natural-map residual of the true Coulomb law for impulses `gamma` (3 nc, N s):
// per contact the natural map of De Saxce's velocity `u + mu ||u_t|| e_n` with the step
// s_i = 3 / trace(N_ii) (kg), divided by s_i (m/s), and the norm relative to max(||r||,
// ||N gamma||). With `shift` (nc, m/s) given, the modified velocity is `u + shift_i e_n`
// instead: the residual of the convex problem whose normal offset is frozen at `shift` (the
// relaxed CCP for shift = 0). 0 at a solution; infinity when the scale is 0 and gamma is not.
double coulombResidual(const ccp::Problem& p, const Eigen::VectorXd& gamma,
                       const Eigen::VectorXd* shift = nullptr);

// The squared per-contact terms of coulombResidual's numerator ((m/s)^2, nc values).
Eigen::VectorXd coulombErrors(const ccp::Problem& p, const Eigen::VectorXd& gamma,
                              const Eigen::VectorXd* shift = nullptr);

}  // namespace rheofeed::bench
