// SPDX-License-Identifier: MIT
#pragma once

/// @file
/// Nonsmooth Gauss-Seidel (NSGS) for the true Coulomb friction problem, after Jean & Moreau and
/// the comparison of Acary, Bremond & Huber ("On solving contact problems with Coulomb friction:
/// formulations and numerical comparisons", INRIA RR-9118, 2018), where NSGS with an exact
/// local solver is the most robust method on rigid granular sets.
///
/// The problem is problem.hpp's with Coulomb's law instead of its convex relaxation: find
/// `gamma` in K with `u = N gamma + r` such that, per contact, De Saxce's modified velocity
/// `u_i + mu_i ||u_t,i|| e_n` lies in the dual cone K_i* and is orthogonal to `gamma_i`
/// (separation, stick, or slide with u_n = 0 and friction opposing the slip). A sweep visits the
/// contacts in turn and solves each one's 3 x 3 Coulomb problem exactly (local_coulomb.cpp:
/// closed forms for take-off and stick, an Alart-Curnier nonsmooth Newton scaled by the
/// contact's own Delassus block with a line search for slip, and a projection fixed point as
/// fallback), with the other contacts' impulses frozen at their latest values; optionally the
/// contacts of one pair of bodies are solved together (NsgsSettings::group_contacts). Matrix-free
/// problems are swept through the generalised velocity `M^-1 D gamma`, touching only the
/// columns of the contact's bodies, so thousands of contacts cost O(nnz(D)) per sweep.
/// Every NsgsSettings::global_newton_interval sweeps, semismooth Newton steps on all contacts at
/// once (global_newton.cpp, a sparse LU factorisation; of an augmented system in (d gamma,
/// M^-1 D d gamma) for matrix-free problems, so that N is never formed) redistribute impulses
/// along the nearly singular directions of N (a box's coplanar corners, rank deficient up to the
/// compliance), which the sweeps correct only at the compliance's pace; they are kept only when
/// they lower the Coulomb residual, and the wait before the next attempt doubles when they do not
/// lower the lowest residual of the solve so far.
///
/// Stopping test: the Coulomb residual of solver.hpp (Result::coulomb_distance: dimensionless
/// natural map with De Saxce's velocity, invariant to the units of N and r), recomputed from
/// drift-free velocities before convergence is declared. Result::residual reports the same
/// number. Settings are NsgsSettings (settings.hpp).

#include "rheofeed/ccp/problem.hpp"
#include "rheofeed/ccp/settings.hpp"

#include <Eigen/Core>

#include <memory>

namespace rheofeed::ccp {

/// NSGS solver with a reusable workspace. Unlike Solver it allocates in every solve (the contact
/// groups and their lists are rebuilt from the problem). Not thread safe. Never throws for bad
/// input (Status::InvalidInput).
class NsgsSolver {
 public:
  /// A solver with default NsgsSettings.
  NsgsSolver();
  /// A solver with the given settings (checked at each solve).
  explicit NsgsSolver(const NsgsSettings& settings);
  /// Releases the workspace.
  ~NsgsSolver();
  /// Moves settings and workspace.
  NsgsSolver(NsgsSolver&&) noexcept;
  /// Moves settings and workspace.
  NsgsSolver& operator=(NsgsSolver&&) noexcept;
  NsgsSolver(const NsgsSolver&) = delete;
  NsgsSolver& operator=(const NsgsSolver&) = delete;

  /// Current settings (read only).
  const NsgsSettings& settings() const { return settings_; }
  /// Current settings, to modify between solves.
  NsgsSettings& settings() { return settings_; }

  /// Solves the Coulomb problem. `gamma` (3 nc impulses, N s, (n, u, v) per contact) is the
  /// warm start on input (projected onto K; see NsgsSettings::warm_start) and on output the
  /// solution (Converged) or the sweep end with the lowest Coulomb residual (MaxIterations),
  /// always in K, except on InvalidInput where it is untouched. Result::iterations counts
  /// sweeps; Result::local_fallbacks and local_unconverged count local solves.
  Result solve(const Problem& problem, Eigen::VectorXd& gamma);

 private:
  struct Workspace;
  NsgsSettings settings_;
  std::unique_ptr<Workspace> workspace_;
};

}  // namespace rheofeed::ccp
