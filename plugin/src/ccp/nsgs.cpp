// SPDX-License-Identifier: MIT
//
// Nonsmooth Gauss-Seidel over contacts for the true Coulomb problem (nsgs.hpp).
//
// Sweep: for each contact i (in the order of NsgsSettings::order), with u_i the current contact
// velocity (all impulses at their latest values) and W = N_ii its Delassus block,
//     q_i = u_i - W gamma_i                (velocity of everything but contact i)
//     g   = local Coulomb solution of (W + eta I, q_i - eta gamma_i)   (local_coulomb.cpp)
//     gamma_i <- Pi_K(gamma_i + omega (g - gamma_i))
// and the change is pushed into the maintained velocities (contact_velocity.hpp: u itself for a
// dense N, the generalised velocity M^-1 D gamma when matrix-free). eta = proximal_weight *
// trace(W) / 3 is an optional proximal term (Rockafellar's proximal point applied contact by
// contact): the fixed points are unchanged (g = gamma_i makes the term vanish), the local
// problem is better conditioned and each update is damped. omega is over- or under-relaxation.
//
// After each sweep the Coulomb residual (solver.hpp) is computed from the maintained
// velocities; below the tolerance it is recomputed from scratch (no round-off drift) before the
// solve is declared converged. The sweep end with the lowest residual is kept and returned when
// the budget runs out.

#include "rheofeed/ccp/nsgs.hpp"

#include "contact_velocity.hpp"
#include "local_coulomb.hpp"
#include "rheofeed/ccp/cone.hpp"
#include "solver_internal.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <vector>

namespace rheofeed::ccp {

namespace {

std::string format(const char* fmt, double a) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, fmt, a);
  return std::string(buffer);
}

// Seed of the shuffled contact order: fixed, so that solves are reproducible.
constexpr unsigned kShuffleSeed = 20181;

}  // namespace

const char* toString(ContactOrder order) {
  switch (order) {
    case ContactOrder::Given:
      return "Given";
    case ContactOrder::Alternating:
      return "Alternating";
    case ContactOrder::Shuffled:
      return "Shuffled";
  }
  return "Unknown";
}

std::string NsgsSettings::validate() const {
  if (max_iterations < 1) return format("max_iterations = %g must be >= 1", max_iterations);
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance)) {
    return format("tolerance = %g must be finite and >= 0", tolerance);
  }
  if (!(residual_rho > 0.0) || !std::isfinite(residual_rho)) {
    return format("residual_rho = %g must be finite and > 0", residual_rho);
  }
  if (!(omega > 0.0 && omega < 2.0)) return format("omega = %g must be in (0, 2)", omega);
  if (order != ContactOrder::Given && order != ContactOrder::Alternating &&
      order != ContactOrder::Shuffled) {
    return "order is not Given, Alternating or Shuffled";
  }
  if (!(proximal_weight >= 0.0) || !std::isfinite(proximal_weight)) {
    return format("proximal_weight = %g must be finite and >= 0", proximal_weight);
  }
  if (local_newton_iterations < 1) {
    return format("local_newton_iterations = %g must be >= 1", local_newton_iterations);
  }
  if (local_projection_iterations < 0) {
    return format("local_projection_iterations = %g must be >= 0", local_projection_iterations);
  }
  if (!(local_tolerance > 0.0) || !std::isfinite(local_tolerance)) {
    return format("local_tolerance = %g must be finite and > 0", local_tolerance);
  }
  if (refresh_interval < 1) return format("refresh_interval = %g must be >= 1", refresh_interval);
  if (!(time_limit_s >= 0.0)) return format("time_limit_s = %g must be >= 0", time_limit_s);
  return {};
}

struct NsgsSolver::Workspace {
  detail::Workspace base;
  std::vector<Eigen::Matrix3d> blocks;  // N_ii (1/kg)
  std::vector<Eigen::Index> order;      // contact visiting order of the current sweep
  Eigen::VectorXd best;                 // sweep end with the lowest Coulomb residual
};

NsgsSolver::NsgsSolver() = default;
NsgsSolver::NsgsSolver(const NsgsSettings& settings) : settings_(settings) {}
NsgsSolver::~NsgsSolver() = default;
NsgsSolver::NsgsSolver(NsgsSolver&&) noexcept = default;
NsgsSolver& NsgsSolver::operator=(NsgsSolver&&) noexcept = default;

namespace {

// One solve's state, shared by its stages.
template <class Contacts>
struct NsgsRun {
  const Problem& problem;
  const NsgsSettings& settings;
  const detail::Deadline& deadline;
  Eigen::VectorXd& gamma;
  detail::Workspace& ws;
  std::vector<Eigen::Matrix3d>& blocks;
  std::vector<Eigen::Index>& order;
  Eigen::VectorXd& best;
  Contacts& contacts;
  Result& result;
  std::mt19937 random{kShuffleSeed};

  // Coulomb residual of gamma with the maintained velocities (ws.u filled first).
  double residual() {
    contacts.updateVelocity();
    return detail::relativeResidual(gamma, ws.u, problem.r, problem.mu, settings.residual_rho, true,
                                    ws);
  }

  double exactResidual() {
    contacts.refresh(gamma);
    return residual();
  }

  void arrangeOrder(int sweep) {
    switch (settings.order) {
      case ContactOrder::Given:
        break;
      case ContactOrder::Alternating:
        std::reverse(order.begin(), order.end());
        break;
      case ContactOrder::Shuffled:
        if (sweep > 1) std::shuffle(order.begin(), order.end(), random);
        break;
    }
  }

  // One Gauss-Seidel sweep over all contacts.
  void sweep() {
    detail::LocalSettings local;
    local.max_newton_iterations = settings.local_newton_iterations;
    local.max_projection_iterations = settings.local_projection_iterations;
    local.tolerance = settings.local_tolerance;
    for (const Eigen::Index i : order) {
      const Eigen::Matrix3d& w = blocks[static_cast<std::size_t>(i)];
      const Eigen::Vector3d old = gamma.segment<3>(3 * i);
      Eigen::Vector3d q = contacts.velocity(i) - w * old;
      Eigen::Matrix3d w_local = w;
      if (settings.proximal_weight > 0.0) {
        const double eta = settings.proximal_weight * w.trace() / 3.0;
        w_local.diagonal().array() += eta;
        q -= eta * old;
      }
      Eigen::Vector3d local_solution = old;
      const detail::LocalOutcome outcome =
          detail::solveLocalCoulomb(w_local, q, problem.mu[i], local, local_solution);
      if (outcome == detail::LocalOutcome::Projection) ++result.local_fallbacks;
      if (outcome == detail::LocalOutcome::Unconverged) {
        ++result.local_fallbacks;
        ++result.local_unconverged;
      }
      Eigen::Vector3d next = local_solution;
      if (settings.omega != 1.0) {
        next = projectOntoCone(old + settings.omega * (local_solution - old), problem.mu[i]);
      }
      const Eigen::Vector3d delta = next - old;
      if (delta[0] != 0.0 || delta[1] != 0.0 || delta[2] != 0.0) {
        gamma.segment<3>(3 * i) = next;
        contacts.applyChange(i, delta);
      }
    }
  }

  // The sweeps; returns the status.
  Status iterate() {
    double best_residual = exactResidual();
    best = gamma;
    if (!std::isfinite(best_residual)) {
      result.message = "NSGS: non-finite residual at the initial guess";
      return Status::NumericalIssue;
    }
    result.residual = best_residual;
    if (best_residual <= settings.tolerance) return Status::Converged;
    for (int k = 1; k <= settings.max_iterations; ++k) {
      arrangeOrder(k);
      sweep();
      result.iterations = k;
      const bool refresh = k % settings.refresh_interval == 0;
      double current = refresh ? exactResidual() : residual();
      if (!std::isfinite(current)) {
        result.message = "NSGS: non-finite residual (impulses or velocities overflowed)";
        gamma = best;
        return Status::NumericalIssue;
      }
      if (current <= settings.tolerance && !refresh) current = exactResidual();
      if (current < best_residual) {
        best_residual = current;
        best = gamma;
      }
      if (current <= settings.tolerance) return Status::Converged;
      if (deadline.expired()) {
        result.message = format("time limit of %g s reached", deadline.limit());
        gamma = best;
        return Status::MaxIterations;
      }
    }
    gamma = best;
    result.message =
        format("NSGS: Coulomb residual %g above the tolerance after the budget", best_residual);
    return Status::MaxIterations;
  }
};

template <class Contacts>
Status runSweeps(const Problem& problem, const NsgsSettings& settings,
                 const detail::Deadline& deadline, Eigen::VectorXd& gamma, detail::Workspace& ws,
                 std::vector<Eigen::Matrix3d>& blocks, std::vector<Eigen::Index>& order,
                 Eigen::VectorXd& best, Result& result) {
  Contacts contacts(problem, problem.r, ws);
  NsgsRun<Contacts> run{problem, settings, deadline, gamma,    ws,
                        blocks,  order,    best,     contacts, result};
  return run.iterate();
}

}  // namespace

Result NsgsSolver::solve(const Problem& problem, Eigen::VectorXd& gamma) {
  const detail::Deadline deadline(settings_.time_limit_s);
  Result result;
  std::string message = settings_.validate();
  if (!message.empty()) {
    message = "invalid NSGS settings: " + message;
  } else if (std::string bad = problem.validate(); !bad.empty()) {
    message = "invalid problem: " + bad;
  }
  if (!message.empty()) {
    result.status = Status::InvalidInput;
    result.message = std::move(message);
    result.solve_time_s = deadline.elapsed();
    return result;
  }
  if (!workspace_) workspace_ = std::make_unique<Workspace>();
  Workspace& w = *workspace_;
  const Eigen::Index nc = problem.numContacts();
  w.base.resize(nc, problem.numDofs());
  detail::computeContactScales(problem, w.base);
  w.blocks.resize(static_cast<std::size_t>(nc));
  w.order.resize(static_cast<std::size_t>(nc));
  for (Eigen::Index i = 0; i < nc; ++i) {
    w.blocks[static_cast<std::size_t>(i)] = problem.diagonalBlock(i);
    w.order[static_cast<std::size_t>(i)] = i;
  }
  w.best.resize(problem.size());
  if (settings_.warm_start && gamma.size() == problem.size() && gamma.allFinite()) {
    detail::projectOntoCones(gamma, problem.mu);
  } else {
    gamma.setZero(problem.size());
  }
  if (nc == 0) {
    result.status = Status::Converged;
  } else if (problem.form == DelassusForm::Dense) {
    result.status = runSweeps<detail::DenseContacts>(problem, settings_, deadline, gamma, w.base,
                                                     w.blocks, w.order, w.best, result);
  } else {
    result.status = runSweeps<detail::MatrixFreeContacts>(
        problem, settings_, deadline, gamma, w.base, w.blocks, w.order, w.best, result);
  }
  detail::multiplyDelassus(problem, gamma, w.base.u, w.base);
  w.base.u += problem.r;
  detail::computeMeasures(gamma, w.base.u, problem.r, problem.mu, settings_.residual_rho, w.base,
                          result);
  result.residual = result.coulomb_distance;
  result.solve_time_s = deadline.elapsed();
  return result;
}

}  // namespace rheofeed::ccp
