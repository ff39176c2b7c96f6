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
#include "global_newton.hpp"
#include "local_coulomb.hpp"
#include "rheofeed/ccp/cone.hpp"
#include "solver_internal.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <random>
#include <vector>

namespace rheofeed::ccp {

namespace {

// Share of the global tolerance a group's local solve must reach (relative to the group's own
// velocity scale, which is at most the problem's).
constexpr double kGroupToleranceShare = 0.01;
// Newton (or Levenberg-Marquardt) iterations and one-contact fallback passes of a group solve.
constexpr int kGroupNewtonIterations = 10;
constexpr int kGroupFallbackPasses = 10;

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
  if (max_iterations < 1) return detail::format("max_iterations = %g must be >= 1", max_iterations);
  if (!(omega > 0.0 && omega < 2.0)) return detail::format("omega = %g must be in (0, 2)", omega);
  if (order != ContactOrder::Given && order != ContactOrder::Alternating &&
      order != ContactOrder::Shuffled) {
    return "order is not Given, Alternating or Shuffled";
  }
  if (!(proximal_weight >= 0.0) || !std::isfinite(proximal_weight)) {
    return detail::format("proximal_weight = %g must be finite and >= 0", proximal_weight);
  }
  if (local_newton_iterations < 1) {
    return detail::format("local_newton_iterations = %g must be >= 1", local_newton_iterations);
  }
  if (local_projection_iterations < 0) {
    return detail::format("local_projection_iterations = %g must be >= 0",
                          local_projection_iterations);
  }
  if (!(local_tolerance > 0.0) || !std::isfinite(local_tolerance)) {
    return detail::format("local_tolerance = %g must be finite and > 0", local_tolerance);
  }
  if (refresh_interval < 1)
    return detail::format("refresh_interval = %g must be >= 1", refresh_interval);
  if (global_newton_interval < 0) {
    return detail::format("global_newton_interval = %g must be >= 0", global_newton_interval);
  }
  if (global_newton_iterations < 1) {
    return detail::format("global_newton_iterations = %g must be >= 1", global_newton_iterations);
  }
  if (global_newton_max_contacts < 0) {
    return detail::format("global_newton_max_contacts = %g must be >= 0",
                          global_newton_max_contacts);
  }
  if (!(global_newton_step_limit > 0.0) || !std::isfinite(global_newton_step_limit)) {
    return detail::format("global_newton_step_limit = %g must be finite and > 0",
                          global_newton_step_limit);
  }
  return detail::checkStopping(tolerance, residual_rho, time_limit_s);
}

struct NsgsSolver::Workspace {
  detail::Workspace base;
  std::vector<Eigen::Matrix3d> blocks;  // N_ii (1/kg)
  std::vector<Eigen::Index> order;      // group visiting order of the current sweep
  Eigen::VectorXd best;                 // sweep end with the lowest Coulomb residual
  // Groups of contacts solved together (contactGroups), and their coupled blocks of N.
  std::vector<std::vector<Eigen::Index>> groups;
  std::vector<detail::GroupMatrix> group_blocks;
  detail::GlobalNewtonWorkspace newton;  // the global Newton steps' matrices
  Eigen::VectorXd candidate;             // the global Newton steps' result
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
  const std::vector<std::vector<Eigen::Index>>& groups;
  const std::vector<detail::GroupMatrix>& group_blocks;
  detail::GlobalNewtonWorkspace& newton;
  Eigen::VectorXd& candidate;
  Contacts& contacts;
  Result& result;
  std::mt19937 random{kShuffleSeed};
  int newton_wait = settings.global_newton_interval;  // sweeps between global Newton attempts
  int next_newton = settings.global_newton_interval;  // sweep of the next attempt

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

  void count(detail::LocalOutcome outcome) {
    if (outcome == detail::LocalOutcome::Projection) ++result.local_fallbacks;
    if (outcome == detail::LocalOutcome::Unconverged) {
      ++result.local_fallbacks;
      ++result.local_unconverged;
    }
  }

  // Contact i's update to `next` (relaxed and projected when omega != 1), pushed into the
  // maintained velocities.
  void update(Eigen::Index i, const Eigen::Vector3d& old, const Eigen::Vector3d& solution) {
    Eigen::Vector3d next = solution;
    if (settings.omega != 1.0) {
      next = projectOntoCone(old + settings.omega * (solution - old), problem.mu[i]);
    }
    const Eigen::Vector3d delta = next - old;
    if (delta[0] != 0.0 || delta[1] != 0.0 || delta[2] != 0.0) {
      gamma.segment<3>(3 * i) = next;
      contacts.applyChange(i, delta);
    }
  }

  void solveContact(Eigen::Index i, const detail::LocalSettings& local) {
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
    count(detail::solveLocalCoulomb(w_local, q, problem.mu[i], local, local_solution));
    update(i, old, local_solution);
  }

  void solveGroup(std::size_t g, const detail::LocalSettings& local) {
    const std::vector<Eigen::Index>& members = groups[g];
    const Eigen::Index k = static_cast<Eigen::Index>(members.size());
    detail::GroupMatrix w = group_blocks[g];
    detail::GroupVector old(3 * k), u(3 * k), mu(k);
    for (Eigen::Index c = 0; c < k; ++c) {
      const Eigen::Index i = members[static_cast<std::size_t>(c)];
      old.segment<3>(3 * c) = gamma.segment<3>(3 * i);
      u.segment<3>(3 * c) = contacts.velocity(i);
      mu[c] = problem.mu[i];
    }
    detail::GroupVector q = u - w * old;
    if (settings.proximal_weight > 0.0) {
      for (Eigen::Index c = 0; c < k; ++c) {
        const double eta = settings.proximal_weight * w.block<3, 3>(3 * c, 3 * c).trace() / 3.0;
        w.block<3, 3>(3 * c, 3 * c).diagonal().array() += eta;
        q.segment<3>(3 * c) -= eta * old.segment<3>(3 * c);
      }
    }
    detail::GroupVector solution = old;
    // A group's block is ill conditioned (rank deficient up to the compliance): its Newton
    // solve is asked for a hundredth of the global tolerance, not the one-contact round-off.
    detail::LocalSettings group_local = local;
    group_local.tolerance = std::max(local.tolerance, kGroupToleranceShare * settings.tolerance);
    // A group that does not settle quickly is left to the next sweep (the budgets below keep a
    // stalled group from costing more than a few sweeps of its contacts).
    group_local.max_newton_iterations =
        std::min(local.max_newton_iterations, kGroupNewtonIterations);
    group_local.max_projection_iterations =
        std::min(local.max_projection_iterations, kGroupFallbackPasses);
    count(detail::solveGroupCoulomb(w, q, mu, group_local, solution));
    for (Eigen::Index c = 0; c < k; ++c) {
      update(members[static_cast<std::size_t>(c)], old.segment<3>(3 * c),
             solution.segment<3>(3 * c));
    }
  }

  // One Gauss-Seidel sweep over all groups (most are single contacts).
  void sweep() {
    detail::LocalSettings local;
    local.max_newton_iterations = settings.local_newton_iterations;
    local.max_projection_iterations = settings.local_projection_iterations;
    local.tolerance = settings.local_tolerance;
    for (const Eigen::Index g : order) {
      const std::vector<Eigen::Index>& members = groups[static_cast<std::size_t>(g)];
      if (members.size() == 1) {
        solveContact(members[0], local);
      } else {
        solveGroup(static_cast<std::size_t>(g), local);
      }
    }
  }

  // Global Newton steps from gamma (residual `current`, maintained velocities exact), kept
  // only when they lower the Coulomb residual; returns the residual of the gamma kept. A kept
  // candidate that does not lower the lowest residual of the solve so far (`best_so_far`) also
  // doubles the wait before the next attempt: the sweeps may have climbed away from a point the
  // Newton steps lead back to, and an attempt at every interval would reset them there each time
  // (measured on a bowl step of 94 contacts: stuck at 1.33e-6 for 700,000 sweeps, which sweeps
  // alone take to 1e-8 in 21,860; now 99,639 sweeps to 1e-6). Refusing such candidates instead
  // solved that step in 49,239 sweeps but on the main demo's first 8 s of reference converged
  // 732 steps of 785 at 459 s of CPU, against 756 at 309 s with this rule (one run each).
  double globalNewtonSteps(double current, double best_so_far) {
    ++result.global_newton_tries;
    const double found = detail::globalNewton(
        problem, gamma, settings.global_newton_iterations, settings.global_newton_step_limit,
        settings.tolerance, settings.residual_rho, deadline, newton, ws, candidate);
    if (found < 0.0) {
      newton_wait *= 2;  // back off: each failed attempt costs many sweeps' worth
      return current;
    }
    candidate.swap(gamma);
    const double trial = exactResidual();
    if (trial < current) {
      ++result.global_newton_kept;
      if (!(trial < best_so_far)) newton_wait *= 2;
      return trial;
    }
    candidate.swap(gamma);
    contacts.refresh(gamma);
    return current;
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
      const bool global = settings.global_newton_interval > 0 &&
                          problem.numContacts() <= settings.global_newton_max_contacts &&
                          k == next_newton;
      if (global) next_newton += newton_wait;
      const bool refresh = global || k % settings.refresh_interval == 0;
      double current = refresh ? exactResidual() : residual();
      if (global && current > settings.tolerance && std::isfinite(current)) {
        current = globalNewtonSteps(current, best_residual);
        next_newton = k + newton_wait;
      }
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
        result.message = detail::format("time limit of %g s reached", deadline.limit());
        gamma = best;
        return Status::MaxIterations;
      }
    }
    gamma = best;
    result.message = detail::format(
        "NSGS: Coulomb residual %g above the tolerance after the budget", best_residual);
    return Status::MaxIterations;
  }
};

template <class Contacts, class Workspace>
Status runSweeps(const Problem& problem, const NsgsSettings& settings,
                 const detail::Deadline& deadline, Eigen::VectorXd& gamma, Workspace& w,
                 Result& result) {
  Contacts contacts(problem, problem.r, w.base);
  NsgsRun<Contacts> run{problem, settings, deadline,       gamma,    w.base,      w.blocks, w.order,
                        w.best,  w.groups, w.group_blocks, w.newton, w.candidate, contacts, result};
  return run.iterate();
}

// Contacts whose columns of D reach the same generalised velocities shared by more than one
// contact (matrix-free: the same pair of bodies, the compliance coordinates of each row being
// its own), or whose rows of N couple to the same contacts (dense), form a group, in the order
// of their first contact; groups are cut at kMaxGroupContacts. Any partition is valid (block
// Gauss-Seidel with exact block solves); this one puts the rank-deficient corners of one body on
// another in one block.
void contactGroups(const Problem& problem, std::vector<std::vector<Eigen::Index>>& groups) {
  const Eigen::Index nc = problem.numContacts();
  std::map<std::vector<Eigen::Index>, std::size_t> by_key;
  groups.clear();
  std::vector<Eigen::Index> key;
  std::vector<int> row_count;
  if (problem.form == DelassusForm::MatrixFree) {
    row_count.assign(static_cast<std::size_t>(problem.d.rows()), 0);
    for (Eigen::Index col = 0; col < problem.d.outerSize(); col += 3) {
      for (SparseMatrix::InnerIterator it(problem.d, col); it; ++it) ++row_count[it.row()];
    }
  }
  for (Eigen::Index i = 0; i < nc; ++i) {
    key.clear();
    if (problem.form == DelassusForm::MatrixFree) {
      for (SparseMatrix::InnerIterator it(problem.d, 3 * i); it; ++it) {
        if (row_count[static_cast<std::size_t>(it.row())] > 1) key.push_back(it.row());
      }
    } else {
      for (Eigen::Index j = 0; j < nc; ++j) {
        if (!problem.delassus.block<3, 3>(3 * i, 3 * j).isZero(0.0)) key.push_back(j);
      }
    }
    auto found = by_key.find(key);
    if (found != by_key.end() &&
        groups[found->second].size() < static_cast<std::size_t>(detail::kMaxGroupContacts)) {
      groups[found->second].push_back(i);
    } else {
      by_key[key] = groups.size();
      groups.push_back({i});
    }
  }
}

// The coupled block of N of every group of more than one contact; matrix-free, column by
// column as D_a^T (M^-1 D_b), touching only the sparse columns of the group's bodies.
void groupBlocks(const Problem& problem, const std::vector<std::vector<Eigen::Index>>& groups,
                 std::vector<detail::GroupMatrix>& blocks) {
  blocks.resize(groups.size());
  Eigen::VectorXd impulse_velocity = Eigen::VectorXd::Zero(problem.numDofs());  // M^-1 D_b
  std::vector<Eigen::Index> touched;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const auto& members = groups[g];
    const Eigen::Index k = static_cast<Eigen::Index>(members.size());
    if (k == 1) continue;
    detail::GroupMatrix& w = blocks[g];
    w.resize(3 * k, 3 * k);
    for (Eigen::Index b = 0; b < k; ++b) {
      for (int axis = 0; axis < 3; ++axis) {
        const Eigen::Index col = 3 * members[static_cast<std::size_t>(b)] + axis;
        if (problem.form == DelassusForm::Dense) {
          for (Eigen::Index a = 0; a < k; ++a) {
            w.block<3, 1>(3 * a, 3 * b + axis) =
                problem.delassus.block<3, 1>(3 * members[static_cast<std::size_t>(a)], col);
          }
          continue;
        }
        touched.clear();
        for (SparseMatrix::InnerIterator it(problem.d, col); it; ++it) {
          for (SparseMatrix::InnerIterator m(problem.minv, it.row()); m; ++m) {
            if (impulse_velocity[m.row()] == 0.0) touched.push_back(m.row());
            impulse_velocity[m.row()] += m.value() * it.value();
          }
        }
        for (Eigen::Index a = 0; a < k; ++a) {
          for (int row_axis = 0; row_axis < 3; ++row_axis) {
            const Eigen::Index row = 3 * members[static_cast<std::size_t>(a)] + row_axis;
            double sum = 0.0;
            for (SparseMatrix::InnerIterator it(problem.d, row); it; ++it) {
              sum += it.value() * impulse_velocity[it.row()];
            }
            w(3 * a + row_axis, 3 * b + axis) = sum;
          }
        }
        for (const Eigen::Index t : touched) impulse_velocity[t] = 0.0;
      }
    }
    w = (0.5 * (w + w.transpose())).eval();
  }
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
  for (Eigen::Index i = 0; i < nc; ++i) {
    w.blocks[static_cast<std::size_t>(i)] = problem.diagonalBlock(i);
  }
  if (settings_.group_contacts) {
    contactGroups(problem, w.groups);
  } else {
    w.groups.assign(static_cast<std::size_t>(nc), {});
    for (Eigen::Index i = 0; i < nc; ++i) w.groups[static_cast<std::size_t>(i)] = {i};
  }
  groupBlocks(problem, w.groups, w.group_blocks);
  w.order.resize(w.groups.size());
  for (std::size_t g = 0; g < w.groups.size(); ++g) w.order[g] = static_cast<Eigen::Index>(g);
  w.best.resize(problem.size());
  w.newton.prepared = false;
  if (settings_.warm_start && gamma.size() == problem.size() && gamma.allFinite()) {
    detail::projectOntoCones(gamma, problem.mu);
  } else {
    gamma.setZero(problem.size());
  }
  if (nc == 0) {
    result.status = Status::Converged;
  } else if (problem.form == DelassusForm::Dense) {
    result.status =
        runSweeps<detail::DenseContacts>(problem, settings_, deadline, gamma, w, result);
  } else {
    result.status =
        runSweeps<detail::MatrixFreeContacts>(problem, settings_, deadline, gamma, w, result);
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
