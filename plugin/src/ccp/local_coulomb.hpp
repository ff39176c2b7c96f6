// SPDX-License-Identifier: MIT
#pragma once

// The one-contact Coulomb friction problem (internal to the cone solver library, used by
// nsgs.cpp; not installed). See local_coulomb.cpp for the method.

#include <Eigen/Core>

namespace rheofeed::ccp::detail {

/// How a local solve ended.
enum class LocalOutcome {
  /// Closed form: the contact separates (q_n >= 0, impulse 0).
  TakeOff,
  /// Closed form: the contact sticks (u = 0 with the impulse inside the cone).
  Stick,
  /// Nonsmooth Newton on the Alart-Curnier function converged (a sliding contact).
  Newton,
  /// Newton stalled; the projection fixed point with local iterations converged.
  Projection,
  /// Neither converged to the local tolerance; the impulse with the lowest local residual is
  /// returned (in the cone).
  Unconverged,
};

/// Local solver settings (see NsgsSettings for their meaning and units).
struct LocalSettings {
  int max_newton_iterations = 30;
  int max_projection_iterations = 200;
  double tolerance = 1e-14;
};

/// Solves the Coulomb problem of one contact: find `r` in the friction cone `K_mu` with
/// `u = W r + q` (m/s), such that De Saxce's modified velocity `u + mu ||u_t|| e_n` lies in the
/// dual cone and is orthogonal to `r` (a separating contact has r = 0, a sticking one u = 0, a
/// sliding one u_n = 0, r on the cone's boundary opposing u_t). `w` is the contact's Delassus
/// block (3 x 3, 1/kg, symmetric positive definite), `q` the velocity of the other impulses
/// (m/s), `mu` >= 0. On entry `r` (N s) is the initial guess (e.g. the last sweep's), on exit the
/// solution. No heap allocation.
LocalOutcome solveLocalCoulomb(const Eigen::Matrix3d& w, const Eigen::Vector3d& q, double mu,
                               const LocalSettings& settings, Eigen::Vector3d& r);

/// The local residual: the natural map of De Saxce's formulation,
/// `||r - Pi_K(r - s (W r + q + mu ||u_t|| e_n))|| / s` (m/s) with `s = 3 / trace(W)` (kg),
/// relative to `max(||q||, ||W r||)`; 0 when both are zero.
double localCoulombResidual(const Eigen::Matrix3d& w, const Eigen::Vector3d& q, double mu,
                            const Eigen::Vector3d& r);

}  // namespace rheofeed::ccp::detail

namespace rheofeed::ccp::detail {

/// Largest group of contacts solved together by solveGroupCoulomb (contacts).
constexpr int kMaxGroupContacts = 8;

/// Dense matrices and vectors of a group's local problem without heap allocation.
using GroupMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3 * kMaxGroupContacts,
                                  3 * kMaxGroupContacts>;
using GroupVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3 * kMaxGroupContacts, 1>;

/// Solves the Coulomb problem of a group of k contacts (2 <= k <= kMaxGroupContacts, e.g. the
/// corners of one box on the floor, whose Delassus block is rank deficient up to the
/// compliance) at once: `w` the group's block of N (3k x 3k, 1/kg), `q` the velocity of
/// everything else (3k, m/s), `mu` (k). Nonsmooth Newton on the group's Alart-Curnier function
/// (each contact scaled by its own diagonal block) with a line search; when it stalls, passes
/// of one-contact solves over the group as fallback. `r` (3k, N s) is the initial guess on
/// entry and the solution on exit (in the cones).
LocalOutcome solveGroupCoulomb(const GroupMatrix& w, const GroupVector& q, const GroupVector& mu,
                               const LocalSettings& settings, GroupVector& r);

}  // namespace rheofeed::ccp::detail
