// SPDX-License-Identifier: MIT
#pragma once

/// @file
/// Settings and results of the cone complementarity solvers (solver.hpp, nsgs.hpp), without
/// Eigen: code that configures a solver or reads its outcome (the reference world's settings and
/// step reports, scenes, commands) includes this header only. The quality measures of Result are
/// defined in solver.hpp's header comment.

#include <limits>
#include <string>

namespace rheofeed::ccp {

/// Iterative method used by Solver.
enum class Method {
  /// Block projected Gauss-Seidel, one 3 x 3 block (contact) at a time.
  Pgs,
  /// Accelerated projected gradient descent (Nesterov) with adaptive step and restart.
  Apgd,
};

/// Printable name of a Method ("PGS", "APGD").
const char* toString(Method method);

/// Outcome of Solver::solve. Starts at NotRun.
enum class Status {
  /// No solve has produced this result.
  NotRun,
  /// The residual is at or below Settings::tolerance (in Coulomb mode: the Coulomb residual is,
  /// or the fixed point moved less than Settings::coulomb_tolerance after a converged inner
  /// solve).
  Converged,
  /// The iteration or time budget ran out first; gamma is the best iterate found (in Coulomb
  /// mode: the shifted outer iterate with the lowest Coulomb residual, its normal impulses
  /// corrected as Settings::coulomb_max_separation says).
  MaxIterations,
  /// A non-finite value appeared during the iterations (an overflow of finite data: impulses,
  /// velocities, or in Coulomb mode the shift mu ||u_t|| or the Coulomb residual); gamma is the
  /// last finite best iterate. Never reported as MaxIterations.
  NumericalIssue,
  /// Problem::validate() or the settings refused the input (e.g. a NaN or infinity in r, mu or
  /// N); gamma is untouched.
  InvalidInput,
};

/// Printable name of a Status ("NotRun", "Converged", ...).
const char* toString(Status status);

/// Solver settings. Defaults are in the class; all are checked by solve().
struct Settings {
  /// Iterative method.
  Method method = Method::Apgd;
  /// Iteration budget of one relaxed solve: PGS sweeps over all contacts, or APGD iterations
  /// (>= 1). In Coulomb mode it applies to each inner solve.
  int max_iterations = 10000;
  /// Stop when the relative residual (see Result::residual and this file's header: dimensionless
  /// and invariant to the units of N and r) is at or below this value (>= 0).
  double tolerance = 1e-8;
  /// Multiplier rho of the per-contact natural map step `s_i = rho / lambda_i` (kg) of the
  /// residual (dimensionless, > 0; 1 uses the PGS block step 3 / trace(N_ii)).
  double residual_rho = 1.0;
  /// PGS over-relaxation (dimensionless, 0 < omega < 2; 1 means none): the block step of contact
  /// i is `min(omega * 3 / trace(N_ii), 1.9 / lambda_max(N_ii))` (unit: impulse per velocity,
  /// kg). The cap keeps each block update a descent step on strongly anisotropic blocks.
  double omega = 1.0;
  /// Use the incoming gamma as the initial guess (projected onto K) when it has the right size
  /// and finite entries; otherwise start from zero.
  bool warm_start = true;
  /// Dense PGS updates `u = N gamma + r` incrementally; recompute it from scratch every this many
  /// sweeps to remove round-off drift (>= 1). Matrix-free PGS does the same for `M^-1 D gamma`.
  int pgs_refresh_interval = 64;
  /// Wall-clock budget of the whole solve (s); 0 means none. When exceeded, the solve stops with
  /// Status::MaxIterations and the best iterate.
  double time_limit_s = 0.0;
  /// Outer fixed-point iterations of the true Coulomb mode (>= 0). 0 solves the convex
  /// relaxation (the CCP). k > 0 solves up to k relaxed problems: the first with the problem's
  /// own r (from the incoming gamma; where nothing slides it is the Coulomb solution), then,
  /// restarting from the incoming gamma, each with `r_n` replaced by `r_n + mu ||u_t||` from the
  /// previous solution, warm-started. It stops when the Coulomb residual (see
  /// Result::coulomb_distance) is at or below tolerance, or when the added term changes by less
  /// than coulomb_tolerance with a converged inner solve; otherwise (Status::MaxIterations) the
  /// shifted iterate with the lowest Coulomb residual is returned (never the relaxed one, whose
  /// sliding contacts separate at mu ||u_t||, unless k == 1), with the frozen-friction normal
  /// correction (see coulomb_max_separation) when it separates a pressed contact.
  int coulomb_outer_iterations = 0;
  /// Coulomb mode stops when `||s_new - s_old|| / max(||r||, ||N gamma||) <= coulomb_tolerance`
  /// (a converged inner solve assumed), where `s_i = mu_i ||u_t,i||` (m/s) is the normal shift
  /// (>= 0, dimensionless and scale invariant like tolerance).
  double coulomb_tolerance = 1e-8;
  /// Coulomb mode, when the fixed point does not settle: the best iterate is returned as is when
  /// no contact that carries a normal impulse separates faster than this (m/s, >= 0; infinity
  /// disables the correction); otherwise its normal impulses are corrected (frozen-friction
  /// normal correction, solver.cpp): Signorini's law is restored with the best iterate's friction
  /// shrunk into the cone of the new normal impulses, so that friction cannot launch a contact.
  double coulomb_max_separation = 0.0;

  /// Empty when the settings are usable, else a message naming the bad field and its value.
  std::string validate() const;
};

/// Order in which NSGS visits the contacts within a sweep.
enum class ContactOrder {
  /// The problem's order every sweep.
  Given,
  /// The problem's order, then reversed, alternately (symmetric Gauss-Seidel).
  Alternating,
  /// A fresh pseudo-random permutation every sweep after the first (fixed seed: reproducible).
  Shuffled,
};

/// Printable name of a ContactOrder ("Given", "Alternating", "Shuffled").
const char* toString(ContactOrder order);

/// Settings of the NSGS true-Coulomb solver (nsgs.hpp). Defaults are in the class; all are
/// checked by NsgsSolver::solve().
struct NsgsSettings {
  /// Sweep budget (>= 1): one sweep solves every contact's local problem once.
  int max_iterations = 1000;
  /// Stop when the Coulomb residual (Result::coulomb_distance, dimensionless, scale invariant)
  /// is at or below this value (finite, >= 0).
  double tolerance = 1e-8;
  /// Multiplier of the residual's per-contact natural map step, as Settings::residual_rho
  /// (dimensionless, > 0).
  double residual_rho = 1.0;
  /// Relaxation of each contact update, `gamma_i <- Pi_K(gamma_i + omega (g - gamma_i))` with g
  /// the local solution (dimensionless, 0 < omega < 2; 1 means none).
  double omega = 1.0;
  /// Contact order within a sweep.
  ContactOrder order = ContactOrder::Given;
  /// Proximal term of the local problems, `eta = proximal_weight * trace(N_ii) / 3` (1/kg) added
  /// to the block and `eta gamma_i` to the local free velocity (dimensionless, >= 0; 0 = off).
  /// The solution is unchanged; each update is damped and rank-deficient blocks regularised.
  double proximal_weight = 0.0;
  /// Use the incoming gamma (projected onto K) as the initial guess when it has the right size
  /// and finite entries; otherwise start from zero.
  bool warm_start = true;
  /// Solve the contacts of one pair of bodies (matrix-free problems: the same generalised
  /// velocities; dense: the same coupling pattern) together, up to 8 at a time, by a Newton
  /// step on their coupled block: the corners of a box on the floor are rank deficient up to
  /// the compliance, and one contact at a time redistributes their normal impulses only at the
  /// compliance's pace. false: one contact at a time.
  bool group_contacts = false;
  /// Nonsmooth Newton iterations of one local solve (>= 1).
  int local_newton_iterations = 30;
  /// Iterations of the local projection fallback when Newton stalls (>= 0).
  int local_projection_iterations = 100;
  /// Local stopping test on the contact's own relative Coulomb residual (finite, > 0).
  double local_tolerance = 1e-13;
  /// Recompute the maintained velocities from scratch every this many sweeps (>= 1) to remove
  /// round-off drift (always before convergence is declared).
  int refresh_interval = 32;
  /// After this many sweeps (>= 0; 0 = never), and again every as many more, up to
  /// global_newton_iterations semismooth Newton steps on the Alart-Curnier function of all
  /// contacts at once (global_newton.cpp: a sparse LU factorisation of the generalised
  /// Jacobian, a limited step length), whose best iterate by the Coulomb residual is kept when
  /// it lowers the residual; an attempt that does not, or whose iterate does not lower the
  /// lowest residual of the solve so far, doubles the wait before the next. They
  /// distribute impulses among coplanar and statically indeterminate contacts (a box's corners
  /// on the floor), which Gauss-Seidel does only at the pace of the compliance; the sweeps
  /// before settle the contacts' states (stick, slide, separate) for them.
  int global_newton_interval = 50;
  /// Newton steps of one global attempt (>= 1).
  int global_newton_iterations = 40;
  /// Problems with more contacts than this (>= 0) take no global Newton steps: the sparse LU
  /// factorisation's fill-in grows with the pile. Measured on the stability matrix's 1000-box
  /// bin: one attempt on 4160 contacts took 61 s with N formed; with the augmented system of
  /// matrix-free problems (global_newton.cpp) attempts at 1,000-3,000 contacts cost 0.2-2.7 s
  /// each and 3 of 29 lowered the residual on the bin's first 0.2 s, so the limit stays.
  int global_newton_max_contacts = 1000;
  /// Longest global Newton step, as a share of the largest impulse of the iterate
  /// (dimensionless, finite, > 0): near a solution the Jacobian's nearly singular directions can
  /// ask for internal impulses far outside the cones.
  double global_newton_step_limit = 0.1;
  /// Wall-clock budget of the whole solve (s); 0 means none (then Status::MaxIterations).
  double time_limit_s = 0.0;

  /// Empty when the settings are usable, else a message naming the bad field and its value.
  std::string validate() const;
};

/// Settings of the interior-point solver (ipm.hpp: IpmSolver). Checked at each solve.
struct IpmSettings {
  /// Interior-point iterations of one convex solve (>= 1).
  int max_iterations = 100;
  /// True Coulomb: stop when the Coulomb residual (Result::coulomb_distance, dimensionless) is
  /// at or below this (finite, >= 0). Convex solves: their own residual's target.
  double tolerance = 1e-8;
  /// Each convex solve of the fixed point stops at this share of `tolerance` (0 < share <= 1).
  double inner_tolerance_share = 0.1;
  /// Fixed-point (outer) iterations of IpmSolver::solve (>= 1).
  int max_outer_iterations = 30;
  /// Multiplier of the residual's natural-map step, as Settings::residual_rho (finite, > 0).
  double residual_rho = 1.0;
  /// True Coulomb: start the shift from the incoming gamma's velocities when it has the right
  /// size and finite entries (else from s = 0).
  bool warm_start = true;
  /// Wall-clock budget of one solve (s); 0 means none.
  double time_limit_s = 0.0;

  /// Empty when usable, else a message naming the bad field and its value.
  std::string validate() const;
};

/// What a solve produced. Measures are defined in this file's header comment; they are NaN
/// when not computed (NotRun, InvalidInput).
struct Result {
  /// Outcome.
  Status status = Status::NotRun;
  /// Details for InvalidInput, NumericalIssue and non-converged Coulomb mode; empty otherwise.
  std::string message;
  /// Iterations performed (PGS sweeps or APGD iterations), summed over Coulomb outer iterations.
  int iterations = 0;
  /// Relaxed problems solved in Coulomb mode (0 when Settings::coulomb_outer_iterations == 0).
  int outer_iterations = 0;
  /// Coulomb mode, when the fixed point did not settle: rounds of the frozen-friction normal
  /// correction applied to the best iterate (normal-only solves, each followed by shrinking the
  /// friction into the cone of the new normal impulses; see Settings::coulomb_outer_iterations).
  /// 0 otherwise.
  int normal_correction_rounds = 0;
  /// True when the last correction round shrank no friction impulse: the returned gamma then
  /// satisfies Signorini's law (gamma_n >= 0, u_n >= 0, gamma_n u_n = 0, to the inner
  /// tolerance) with friction in the cone. False when the rounds ran out (the normal velocity
  /// then carries the effect of the last shrink) or no correction was made.
  bool normal_correction_settled = false;
  /// Contacts whose friction impulse the correction set to zero (counted once per round):
  /// after 10 x coulomb_outer_iterations shrinking rounds, a contact whose friction still exceeds
  /// the cone of its corrected normal impulse loses its friction for the step, which ends the
  /// correction in at most nc more rounds.
  int friction_dropped_contacts = 0;
  /// Coulomb mode, when the fixed point did not settle: the largest normal velocity (m/s) of a
  /// contact carrying a normal impulse in the best iterate, before any correction (0 otherwise).
  double best_iterate_separation = 0.0;
  /// Relative residual (dimensionless, scale invariant; this file's header) of the relaxed
  /// problem solved. In Coulomb mode: of the inner solve that produced the returned gamma, with
  /// its shifted `r`.
  double residual = std::numeric_limits<double>::quiet_NaN();
  /// Distance of `u` to the dual cones (m/s), for the problem's own `r`.
  double dual_infeasibility = std::numeric_limits<double>::quiet_NaN();
  /// `sum_i |gamma_i . u_i|` (N m), for the problem's own `r`.
  double complementarity = std::numeric_limits<double>::quiet_NaN();
  /// `1/2 gamma^T N gamma + r^T gamma` (J), for the problem's own `r`.
  double objective = std::numeric_limits<double>::quiet_NaN();
  /// Relative residual of the true Coulomb law (dimensionless), for the problem's own `r`.
  double coulomb_distance = std::numeric_limits<double>::quiet_NaN();
  /// NSGS: local contact solves whose nonsmooth Newton stalled and that took the projection
  /// fallback, summed over sweeps (0 for PGS and APGD).
  int local_fallbacks = 0;
  /// NSGS: local solves that met neither Newton's nor the fallback's tolerance (their best
  /// impulse was used), summed over sweeps; included in local_fallbacks.
  int local_unconverged = 0;
  /// NSGS: global Newton attempts (NsgsSettings::global_newton_interval) and those kept (they
  /// lowered the Coulomb residual).
  int global_newton_tries = 0;
  int global_newton_kept = 0;
  /// Wall-clock time of solve() (s).
  double solve_time_s = 0.0;
};

}  // namespace rheofeed::ccp
