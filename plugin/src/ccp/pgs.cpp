// SPDX-License-Identifier: MIT
//
// Block projected Gauss-Seidel for the cone complementarity problem (Anitescu & Tasora,
// "An iterative approach for cone complementarity problems for nonsmooth dynamics", Comput.
// Optim. Appl. 2010; Tasora & Anitescu, CMAME 2011).
//
// One sweep visits the contacts in order; contact i takes a projected gradient step on its own
// 3 x 3 block with the impulses of the others frozen at their latest values:
//
//     gamma_i <- Pi_{K_i}(gamma_i - s_i u_i),   u_i = (N gamma + r)_i,
//     s_i = min(omega eta_i, 1.9 / lambda_max(N_ii)),   eta_i = 3 / trace(N_ii)
//
// eta_i is the inverse of the block's mean eigenvalue (Tasora & Anitescu). The cap makes every
// block update a descent step of the objective for any omega: on strongly anisotropic blocks
// (lambda_max > 0.63 trace, e.g. the Rover problems of fc3d) the plain step overshoots along the
// stiff direction and the iteration diverges. Isotropic blocks (N_ii = w I) are solved exactly in
// one step when omega = 1.
//
// u_i must reflect the contacts already updated in this sweep, so after each contact the change
// delta_i is pushed into a maintained quantity instead of recomputing u from scratch:
//  - dense N: u itself, u += N(:, 3i..3i+2) delta_i (three contiguous columns, skipped when
//    delta_i = 0, which is the case of every separated contact);
//  - matrix free: the generalised velocity w = M^-1 D gamma, w += M^-1 D_i delta_i, and
//    u_i = D_i^T w + r_i (Tasora & Anitescu's velocity-based loop: only the sparse columns of
//    the contact's bodies are touched).
// The maintained quantity is recomputed from scratch every Settings::pgs_refresh_interval sweeps
// and before convergence is declared, so round-off drift never decides the answer.

#include "contact_velocity.hpp"
#include "rheofeed/ccp/cone.hpp"
#include "solver_internal.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace rheofeed::ccp::detail {

namespace {

// Cap of the block step times the largest eigenvalue of the block's symmetric part. A projected
// gradient step of length s on block i decreases the objective when s lambda_max(N_ii) < 2; a
// margin below 2 keeps the stiffest direction contracting (factor |1 - 1.9| = 0.9 per sweep).
// The Rover problems of fc3d have blocks with lambda_max > 2 trace / 3, where 3 / trace(N_ii)
// alone overshoots and PGS diverges.
constexpr double kMaxStepTimesCurvature = 1.9;

template <class Contacts>
InnerOutcome pgsLoop(Contacts& contacts, const Problem& problem, const Eigen::VectorXd& r,
                     const Eigen::VectorXd& mu, const Settings& settings, const Deadline& deadline,
                     Eigen::VectorXd& gamma, Workspace& ws) {
  const Eigen::Index nc = problem.numContacts();
  const double rho = settings.residual_rho;
  for (Eigen::Index i = 0; i < nc; ++i) {
    const Eigen::Matrix3d block = problem.diagonalBlock(i);
    const Eigen::Matrix3d symmetric = 0.5 * (block + block.transpose());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(symmetric, Eigen::EigenvaluesOnly);
    ws.eta[i] = std::min(settings.omega * 3.0 / block.trace(),
                         kMaxStepTimesCurvature / eigen.eigenvalues()[2]);
  }

  InnerOutcome out;
  contacts.refresh(gamma);
  contacts.updateVelocity();
  out.residual = relativeResidual(gamma, ws.u, r, mu, rho, false, ws);
  ws.best = gamma;
  double best_residual = out.residual;
  if (!std::isfinite(out.residual)) {
    out.status = Status::NumericalIssue;
    out.issue = "PGS: non-finite residual at the initial guess";
    return out;
  }
  if (out.residual <= settings.tolerance) {
    out.status = Status::Converged;
    return out;
  }

  out.status = Status::MaxIterations;
  for (int sweep = 1; sweep <= settings.max_iterations; ++sweep) {
    for (Eigen::Index i = 0; i < nc; ++i) {
      const Eigen::Vector3d old_impulse = gamma.segment<3>(3 * i);
      const Eigen::Vector3d new_impulse =
          projectOntoCone(old_impulse - ws.eta[i] * contacts.velocity(i), mu[i]);
      const Eigen::Vector3d delta = new_impulse - old_impulse;
      if (delta[0] != 0.0 || delta[1] != 0.0 || delta[2] != 0.0) {
        gamma.segment<3>(3 * i) = new_impulse;
        contacts.applyChange(i, delta);
      }
    }
    out.iterations = sweep;
    const bool refreshed = sweep % settings.pgs_refresh_interval == 0;
    if (refreshed) contacts.refresh(gamma);
    contacts.updateVelocity();
    double residual = relativeResidual(gamma, ws.u, r, mu, rho, false, ws);
    if (!std::isfinite(residual)) {
      out.status = Status::NumericalIssue;
      out.issue = "PGS: non-finite residual (impulses or velocities overflowed)";
      break;
    }
    if (residual <= settings.tolerance && !refreshed) {
      // Confirm with drift-free velocities before declaring convergence.
      contacts.refresh(gamma);
      contacts.updateVelocity();
      residual = relativeResidual(gamma, ws.u, r, mu, rho, false, ws);
    }
    if (residual < best_residual) {
      best_residual = residual;
      ws.best = gamma;
    }
    if (residual <= settings.tolerance) {
      out.status = Status::Converged;
      break;
    }
    if (deadline.expired()) {
      out.timed_out = true;
      break;
    }
  }
  if (out.status != Status::Converged) gamma = ws.best;
  out.residual = best_residual;
  return out;
}

}  // namespace

InnerOutcome runPgs(const Problem& problem, const Eigen::VectorXd& r, const Eigen::VectorXd& mu,
                    const Settings& settings, const Deadline& deadline, Eigen::VectorXd& gamma,
                    Workspace& ws) {
  if (problem.form == DelassusForm::Dense) {
    DenseContacts contacts(problem, r, ws);
    return pgsLoop(contacts, problem, r, mu, settings, deadline, gamma, ws);
  }
  MatrixFreeContacts contacts(problem, r, ws);
  return pgsLoop(contacts, problem, r, mu, settings, deadline, gamma, ws);
}

}  // namespace rheofeed::ccp::detail
