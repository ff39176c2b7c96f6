// SPDX-License-Identifier: MIT
#pragma once

// Internal pieces shared by solver.cpp, pgs.cpp, apgd.cpp, nsgs.cpp and ipm.cpp: the workspace,
// the Delassus products, the residual, the inner (relaxed) solvers and the settings checks. Not
// installed.

#include "rheofeed/ccp/problem.hpp"
#include "rheofeed/ccp/solver.hpp"

#include <Eigen/Core>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace rheofeed::ccp::detail {

/// `fmt` (one %g) applied to `a`: the settings checks' messages.
inline std::string format(const char* fmt, double a) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, fmt, a);
  return std::string(buffer);
}

/// The checks NsgsSettings and IpmSettings share: a finite tolerance >= 0, a finite
/// residual_rho > 0 and a time limit >= 0 (s). Empty when they pass, else the message.
inline std::string checkStopping(double tolerance, double residual_rho, double time_limit_s) {
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance)) {
    return format("tolerance = %g must be finite and >= 0", tolerance);
  }
  if (!(residual_rho > 0.0) || !std::isfinite(residual_rho)) {
    return format("residual_rho = %g must be finite and > 0", residual_rho);
  }
  if (!(time_limit_s >= 0.0)) return format("time_limit_s = %g must be >= 0", time_limit_s);
  return {};
}

/// Range of squared norms summed directly by safeNorm(): below, subnormal squares lose digits;
/// above, the sum may have overflowed.
constexpr double kMinSafeSquaredNorm =
    std::numeric_limits<double>::min() / std::numeric_limits<double>::epsilon();
constexpr double kMaxSafeSquaredNorm = 0.5 * std::numeric_limits<double>::max();

/// Preallocated vectors. resize() only allocates when a size changes.
struct Workspace {
  // Contact space (3 nc).
  Eigen::VectorXd u;             // contact velocity N gamma + r of the current iterate
  Eigen::VectorXd r_shifted;     // Coulomb mode: r with mu ||u_t|| added to the normal rows
  Eigen::VectorXd iterate;       // APGD gamma_k, PGS current gamma
  Eigen::VectorXd n_iterate;     // APGD N gamma_k
  Eigen::VectorXd next;          // APGD gamma_{k+1}
  Eigen::VectorXd n_next;        // APGD N gamma_{k+1}
  Eigen::VectorXd y;             // APGD extrapolated point
  Eigen::VectorXd n_y;           // APGD N y
  Eigen::VectorXd best;          // best iterate by residual
  Eigen::VectorXd coulomb_best;  // Coulomb mode: the outer iterate with the lowest Coulomb residual
  Eigen::VectorXd coulomb_start;  // Coulomb mode: the incoming gamma (start of the shift iteration)
  Eigen::VectorXd friction;       // frozen-friction correction: gamma with its normals zeroed
  Eigen::VectorXd r_normal;       // frozen-friction correction: r + N friction
  Eigen::VectorXd map;            // velocity-form natural map of the residual (m/s)
  // Contacts (nc).
  Eigen::VectorXd lambda;     // mean eigenvalue trace(N_ii) / 3 of each diagonal block (1/kg)
  Eigen::VectorXd eta;        // PGS block step 3 / trace(N_ii)
  Eigen::VectorXd shift;      // Coulomb mode: current s_i = mu_i ||u_t,i||
  Eigen::VectorXd shift_new;  // Coulomb mode: next s_i
  Eigen::VectorXd zero_mu;    // frozen-friction correction: mu = 0 (the normal-only problem)
  // Generalised velocities (ndof), matrix-free only.
  Eigen::VectorXd dof_a;
  Eigen::VectorXd dof_b;

  void resize(Eigen::Index nc, Eigen::Index ndof);
};

/// Wall-clock budget of one Solver::solve call.
class Deadline {
 public:
  explicit Deadline(double limit_s) : start_(std::chrono::steady_clock::now()), limit_s_(limit_s) {}
  /// Seconds since construction.
  double elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  /// True when a limit is set and exceeded.
  bool expired() const { return limit_s_ > 0.0 && elapsed() > limit_s_; }
  double limit() const { return limit_s_; }

 private:
  std::chrono::steady_clock::time_point start_;
  double limit_s_;
};

/// What an inner (relaxed) solve reports back.
struct InnerOutcome {
  Status status = Status::NotRun;
  int iterations = 0;
  /// Relative residual (relativeResidual()) of the returned iterate.
  double residual = 0.0;
  /// True when the time budget stopped the solve.
  bool timed_out = false;
  /// Static description of a numerical issue (nullptr otherwise).
  const char* issue = nullptr;
};

/// `y = N x` (no r), using ws.dof_a / ws.dof_b when matrix-free. `y` must not alias `x`.
void multiplyDelassus(const Problem& problem, const Eigen::VectorXd& x, Eigen::VectorXd& y,
                      Workspace& ws);

/// Euclidean norm of `x` that neither overflows nor underflows: the plain sum of squares when
/// it is a normal number, else the norm of `x / max|x_i|` times `max|x_i|`. Non-finite entries
/// give a non-finite result. No heap allocation (x may be an expression).
template <class Derived>
double safeNorm(const Eigen::MatrixBase<Derived>& x) {
  const double squared = x.squaredNorm();
  if (squared >= kMinSafeSquaredNorm && squared <= kMaxSafeSquaredNorm) return std::sqrt(squared);
  if (x.size() == 0) return 0.0;
  if (!x.allFinite()) return std::numeric_limits<double>::quiet_NaN();
  const double largest = x.cwiseAbs().maxCoeff();
  if (largest == 0.0) return 0.0;
  return largest * (x / largest).norm();
}

/// Fills ws.lambda with the mean eigenvalue trace(N_ii) / 3 (1/kg, > 0 for a valid problem) of
/// every diagonal block. Called once per Solver::solve.
void computeContactScales(const Problem& problem, Workspace& ws);

/// The dimensionless relative residual of solver.hpp (Result::residual): with
/// `v_i = (lambda_i / rho) (gamma_i - Pi_K(gamma_i - (rho / lambda_i) u_i))` (m/s),
/// `||v|| / max(||r||, ||u - r||)`, and 0 when both scales and v are zero. With `coulomb`, u_n is
/// replaced by De Saxce's `u_n + mu ||u_t||` (Result::coulomb_distance). Uses ws.lambda and
/// ws.map. Non-finite data give a non-finite result.
double relativeResidual(const Eigen::VectorXd& gamma, const Eigen::VectorXd& u,
                        const Eigen::VectorXd& r, const Eigen::VectorXd& mu, double rho,
                        bool coulomb, Workspace& ws);

/// Fills result's dual_infeasibility, complementarity, objective and coulomb_distance for
/// impulses gamma with u = N gamma + r (u given). Uses ws.lambda and ws.map.
void computeMeasures(const Eigen::VectorXd& gamma, const Eigen::VectorXd& u,
                     const Eigen::VectorXd& r, const Eigen::VectorXd& mu, double rho, Workspace& ws,
                     Result& result);

/// Projects every contact block of `gamma` onto its friction cone, in place.
void projectOntoCones(Eigen::VectorXd& gamma, const Eigen::VectorXd& mu);

/// Relaxed solve by block PGS. On entry `gamma` is in K; on exit it is the last iterate.
/// `r` is the free velocity to use (the problem's or the Coulomb-shifted one) and `mu` the
/// friction coefficients (the problem's, or zeros for the frozen-friction normal problem of
/// solver.cpp); only the Delassus operator is taken from `problem`.
InnerOutcome runPgs(const Problem& problem, const Eigen::VectorXd& r, const Eigen::VectorXd& mu,
                    const Settings& settings, const Deadline& deadline, Eigen::VectorXd& gamma,
                    Workspace& ws);

/// Relaxed solve by APGD (arguments as runPgs). On entry `gamma` is in K; on exit it is the
/// best iterate.
InnerOutcome runApgd(const Problem& problem, const Eigen::VectorXd& r, const Eigen::VectorXd& mu,
                     const Settings& settings, const Deadline& deadline, Eigen::VectorXd& gamma,
                     Workspace& ws);

}  // namespace rheofeed::ccp::detail
