// SPDX-License-Identifier: MIT
#pragma once

/// @file
/// The cone complementarity problem (CCP) of one time step, in contact space.
///
/// With `nc` contacts, impulses `gamma` (3 nc, unit N s) and contact velocities `u` (3 nc, m/s)
/// are stacked per contact in the contact frame order (n, u, v): normal first, then the two
/// tangential directions. The problem is
///
///     find gamma in K = K_mu1 x ... x K_munc   (K_mu = {||gamma_t|| <= mu gamma_n})
///     with u = N gamma + r in K* (u_n >= mu ||u_t||) and gamma . u = 0,
///
/// i.e. the optimality conditions of `min_{gamma in K} 1/2 gamma^T N gamma + r^T gamma`.
/// Here `N = D^T M^-1 D` is the Delassus operator (3 nc x 3 nc, velocity per impulse: (m/s)/(N s)
/// = 1/kg), `D` (ndof x 3 nc) maps contact impulses to generalised
/// impulses, so `D^T v` is the contact-frame velocity of generalised velocities `v`, and
/// `r = D^T v_free + b` (m/s) with `v_free = v + h M^-1 f` and per contact
/// `b_i = [b_n; c_t]`: `b_n` the normal stabilisation term (e.g. `phi/h`, clamped) and `c_t` the
/// rheonomic tangential term (see buildContactOffset). Sign convention: `u = N gamma + r` is the
/// contact velocity at the end of the step (normal component positive when separating) and
/// friction impulses oppose the tangential part of `u`.

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <string>

namespace rheofeed::ccp {

/// Column-major sparse matrix of doubles used for `D` and `M^-1`.
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// How the Delassus operator `N` is given.
enum class DelassusForm {
  /// `N` stored explicitly in Problem::delassus (3 nc x 3 nc).
  Dense,
  /// `N x = D^T (M^-1 (D x))` with Problem::d and Problem::minv; `N` is never formed.
  MatrixFree,
};

/// Printable name of a DelassusForm ("Dense", "MatrixFree").
const char* toString(DelassusForm form);

/// One cone complementarity problem. Plain data: fill the fields directly or use makeDense /
/// makeMatrixFree, then call validate() (Solver::solve validates too). All vectors are stacked
/// per contact in (n, u, v) order.
struct Problem {
  /// Which representation of `N` the solver uses.
  DelassusForm form = DelassusForm::Dense;
  /// Dense Delassus operator `N` (3 nc x 3 nc, 1/kg); used when form == Dense. It should
  /// be symmetric positive semidefinite; a slightly non-symmetric `N` is accepted (the solvers
  /// then solve the variational inequality with `u = N gamma + r` as written).
  Eigen::MatrixXd delassus;
  /// Contact Jacobian transpose `D` (ndof x 3 nc): column `3 i + k` is the generalised direction
  /// of contact `i`'s axis k (k = 0 normal, 1 u, 2 v); used when form == MatrixFree.
  SparseMatrix d;
  /// Inverse generalised mass `M^-1` (ndof x ndof, 1/kg and 1/(kg m^2)), symmetric positive
  /// definite, typically block diagonal (one block per body); used when form == MatrixFree.
  SparseMatrix minv;
  /// Free contact velocity `r = D^T v_free + b` (3 nc, m/s): the value of `u` when gamma = 0.
  Eigen::VectorXd r;
  /// Friction coefficient of each contact (nc, dimensionless, finite, >= 0).
  Eigen::VectorXd mu;

  /// A problem with an explicit Delassus matrix `delassus` (3 nc x 3 nc).
  static Problem makeDense(Eigen::MatrixXd delassus, Eigen::VectorXd r, Eigen::VectorXd mu);

  /// A matrix-free problem: `N = d^T minv d` with `d` ndof x 3 nc and `minv` ndof x ndof.
  static Problem makeMatrixFree(SparseMatrix d, SparseMatrix minv, Eigen::VectorXd r,
                                Eigen::VectorXd mu);

  /// Number of contacts `nc` (the size of mu).
  Eigen::Index numContacts() const { return mu.size(); }

  /// Size of the contact space, 3 nc.
  Eigen::Index size() const { return 3 * mu.size(); }

  /// Number of generalised velocities (rows of d) for a matrix-free problem, 0 for a dense one.
  Eigen::Index numDofs() const { return form == DelassusForm::MatrixFree ? d.rows() : 0; }

  /// The 3 x 3 diagonal block `N_ii` of contact `contact` (0-based), computed without forming
  /// `N` in the matrix-free case. Requires consistent sizes (see validate()). No heap allocation.
  Eigen::Matrix3d diagonalBlock(Eigen::Index contact) const;

  /// `N gamma + r` (3 nc, m/s) for impulses `gamma` (3 nc, N s). Convenience: allocates.
  Eigen::VectorXd contactVelocity(const Eigen::VectorXd& gamma) const;

  /// The Delassus matrix as a dense matrix (`d^T minv d` when matrix-free). Allocates.
  Eigen::MatrixXd denseDelassus() const;

  /// Checks the problem and returns an empty string when it is usable, else a message naming
  /// the first bad value: a size mismatch, a non-finite entry with its index, a negative or
  /// non-finite friction coefficient with its contact index, a diagonal block `N_ii` whose
  /// symmetric part is not positive definite (contact index), or, when matrix-free, a
  /// non-positive diagonal of `minv` or a non positive definite diagonal block of `minv`
  /// (blocks up to 12 x 12 are checked exactly; larger coupled blocks only through their
  /// diagonal and the `N_ii` test). Does not allocate when the problem is valid.
  std::string validate() const;
};

/// Normal stabilisation term `b_n` (m/s) for a contact of signed gap `phi` (m, positive when
/// separated, negative when penetrating) and time step `h` (s > 0): `max(phi / h,
/// -max_recovery_speed)`. A penetration is thus pushed out at most at `max_recovery_speed` (m/s,
/// >= 0; use infinity for no clamp) and an open gap may close within the step.
double normalStabilisation(double phi, double h, double max_recovery_speed);

/// Builds `r = d^T v_free + b` (3 nc, m/s) where, per contact i, `b_i = [normal_term[i];
/// tangential_term[2 i]; tangential_term[2 i + 1]]`.
///
/// - `d`: ndof x 3 nc contact Jacobian transpose (see Problem::d);
/// - `v_free`: ndof generalised velocities after the non-contact forces, `v + h M^-1 f`;
/// - `normal_term`: nc normal terms `b_n` (m/s), e.g. normalStabilisation();
/// - `tangential_term`: 2 nc rheonomic terms `c_t` (m/s) along (u, v), added as is.
///
/// `c_t` makes `u_t = D_t^T v + c_t` the slip that friction opposes: with `D_t^T v` the velocity
/// of the surface body relative to the part (surface minus part) and `c_t` the surface velocity
/// of a stationary feeder geom, `u_t` is (surface + c_t) minus part; if `D_t^T v` is part minus
/// surface, pass `-c_t`. The normal row is unchanged by the rheonomic term.
///
/// Returns an empty string on success (then `r` is resized and filled), else a message naming
/// the size mismatch (`r` untouched).
std::string buildContactOffset(const SparseMatrix& d, const Eigen::VectorXd& v_free,
                               const Eigen::VectorXd& normal_term,
                               const Eigen::VectorXd& tangential_term, Eigen::VectorXd& r);

}  // namespace rheofeed::ccp
