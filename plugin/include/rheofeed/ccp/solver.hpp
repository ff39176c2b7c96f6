// SPDX-License-Identifier: MIT
#pragma once

/// @file
/// Iterative solvers for the cone complementarity problem of problem.hpp: block projected
/// Gauss-Seidel (Tasora & Anitescu) and APGD, Nesterov's accelerated projected gradient
/// (Mazhar, Heyn, Negrut & Tasora, ACM TOG 2015), with an optional outer fixed point that turns
/// the convex relaxation into the true Coulomb law (Acary, Cadoux, Lemarechal & Malick 2011).
///
/// A solver is Settings + Problem + a workspace owned by Solver + a Result. Once a Solver has
/// solved a problem of a given size (nc contacts, ndof generalised velocities), later solves of
/// problems of the same size do not allocate on the heap (unless they fail: error messages are
/// strings).
///
/// Quality measures (Result), all computed from the returned gamma with `u = N gamma + r`, with
/// per contact i the friction cone K_i, its dual K_i*, `lambda_i = trace(N_ii) / 3` (1/kg, the
/// block's mean eigenvalue) and `rho = Settings::residual_rho` (dimensionless):
/// - residual (the stopping test), dimensionless and invariant to scaling the problem
///   (`N -> a N`, `r -> b r` maps solutions by `gamma -> (b / a) gamma`, `u -> b u` and leaves
///   it unchanged; PGS and APGD then take the same iterations):
///       `||v|| / max(||r||, ||N gamma||)`,  `v_i = (gamma_i - Pi_K(gamma_i - s_i u_i)) / s_i`,
///   with `s_i = rho / lambda_i` (kg) the PGS block step, so `v` is the natural map of the CCP in
///   velocity units (m/s; `v_i = u_i` for a sticking contact, 0 for a separated one). The
///   denominator (m/s) is the problem's own velocity scale; it is zero only when `u = 0` and
///   `N gamma = 0`, where `v = 0` too and the residual is defined as 0 (no absolute floor: a
///   problem with `r` scaled by 1e-9 is solved as the unscaled one). Norms are computed without
///   overflow or underflow (data from about 1e-150 to 1e300 is handled).
/// - dual_infeasibility: `sqrt(sum_i dist(u_i, K_i*)^2)` with `dist(u, K*) = ||Pi_K(-u)||` (m/s),
///   how far the velocities are from the relaxed law `u_n >= mu ||u_t||`.
/// - complementarity: `sum_i |gamma_i . u_i|` (N m), zero at a solution (per-contact absolute
///   values, so that contacts cannot cancel each other).
/// - objective: `1/2 gamma^T N gamma + r^T gamma` (J), minimal at the solution.
/// - coulomb_distance: the residual of the true Coulomb law, `u_n` replaced by
///   `u_n + mu ||u_t||` (De Saxce's modified velocity) in `v`, same normalisation as residual.
///   It equals the relaxed residual where no contact slides.
/// The absolute measures (dual_infeasibility, complementarity, objective) are not scale invariant
/// and not used for stopping; they are reported as computed.

#include "rheofeed/ccp/problem.hpp"
#include "rheofeed/ccp/settings.hpp"

#include <Eigen/Core>

#include <memory>

namespace rheofeed::ccp {

/// Cone complementarity solver with a reusable workspace. Not thread safe: use one Solver per
/// thread. Never throws for bad input (Status::InvalidInput).
class Solver {
 public:
  /// A solver with default Settings.
  Solver();
  /// A solver with the given settings (checked at each solve).
  explicit Solver(const Settings& settings);
  /// Releases the workspace.
  ~Solver();
  /// Moves settings and workspace.
  Solver(Solver&&) noexcept;
  /// Moves settings and workspace.
  Solver& operator=(Solver&&) noexcept;
  /// Not copyable: the workspace is per solver.
  Solver(const Solver&) = delete;
  /// Not copyable: the workspace is per solver.
  Solver& operator=(const Solver&) = delete;

  /// Current settings (read only).
  const Settings& settings() const { return settings_; }
  /// Current settings, to modify between solves.
  Settings& settings() { return settings_; }

  /// Solves `problem`. `gamma` (3 nc impulses, N s, (n, u, v) per contact) is the warm start on
  /// input (see Settings::warm_start) and the best iterate on output (always in K), except on
  /// InvalidInput where it is untouched.
  Result solve(const Problem& problem, Eigen::VectorXd& gamma);

 private:
  struct Workspace;
  Settings settings_;
  std::unique_ptr<Workspace> workspace_;
};

}  // namespace rheofeed::ccp
