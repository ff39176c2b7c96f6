// SPDX-License-Identifier: MIT
// Contact stages of World::step (world.hpp, "Contacts", "Stabilisation", "Rheonomic term"):
// the rows of each contact (frame, free contact velocity r, Jacobian columns), the cone
// complementarity problem, the warm start, the solve and its fallbacks, and the contact records.
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "world_internal.hpp"

namespace rheofeed::reference {

using detail::toEigen;
using detail::toVec3;

// One row triple per contact: the frame (n, t1 along the surface velocity, t2), the free
// contact velocity r (with the ERP push or the restitution target and the rheonomic term) and
// the entries of D. Writes c.frames, c.r, c.mu, c.d_entries.
void contactRowsStage(StepContext& c_step) {
  WorldState& s = c_step.s;
  const Settings& cfg = c_step.cfg;
  const double h = c_step.h;
  const int nc = c_step.nc;
  const Eigen::VectorXd& v_free = c_step.v_free;
  const Eigen::VectorXd& v_pre = c_step.v_pre;
  std::vector<Eigen::Triplet<double>>& d_entries = c_step.d_entries;
  d_entries.reserve(static_cast<std::size_t>(nc) * 3 * 12);
  Eigen::VectorXd& r = c_step.r;
  Eigen::VectorXd& mu = c_step.mu;
  r.resize(3 * nc);
  mu.resize(nc);
  std::vector<Matrix3d>& frames = c_step.frames;
  frames.resize(static_cast<std::size_t>(nc));
  for (int i = 0; i < nc; ++i) {
    const WorldState::RawContact& c = s.raw[static_cast<std::size_t>(i)];
    const Vector3d c_rel = s.surfaceVelocity(c.g2, c.p, c.n, c.mu, c.a) -
                           s.surfaceVelocity(c.g1, c.p, -c.n, c.mu, c.b);
    const Vector3d c_t = c_rel - c_rel.dot(c.n) * c.n;
    Vector3d t1, t2;
    const double speed = c_t.norm();
    if (speed > detail::kMinSurfaceSpeed) {
      t1 = c_t / speed;
      t2 = c.n.cross(t1);
    } else {
      detail::planeSpace(c.n, t1, t2);
    }
    Matrix3d& f = frames[static_cast<std::size_t>(i)];
    f.col(0) = c.n;
    f.col(1) = t1;
    f.col(2) = t2;
    const Vector3d rel_free = s.pointVelocity(c.a, c.p, v_free) - s.pointVelocity(c.b, c.p, v_free);
    const double push = std::min(cfg.erp * std::max(c.depth - cfg.surface_layer, 0.0) / h,
                                 cfg.max_correcting_velocity);
    // Restitution as ODE's dContactBounce: when the pre-step approach speed exceeds
    // bounce_velocity, the normal row targets u_n+ >= e * approach, or the ERP push if that is
    // larger (the push alone is capped by max_correcting_velocity, the bounce is not).
    double target = push;
    if (cfg.restitution > 0) {
      const double approach =
          -c.n.dot(s.pointVelocity(c.a, c.p, v_pre) - s.pointVelocity(c.b, c.p, v_pre));
      if (approach > cfg.bounce_velocity) target = std::max(target, cfg.restitution * approach);
    }
    r(3 * i) = c.n.dot(rel_free) - target;
    r(3 * i + 1) = t1.dot(rel_free) - t1.dot(c_t);
    r(3 * i + 2) = t2.dot(rel_free) - t2.dot(c_t);
    mu(i) = c.mu;
    for (int k = 0; k < 3; ++k) {
      const Vector3d dir = f.col(k);
      for (int side = 0; side < 2; ++side) {
        const BodyId b = side == 0 ? c.a : c.b;
        if (!s.isDynamic(b)) continue;
        const double sign = side == 0 ? 1.0 : -1.0;
        const Vector3d arm = c.p - toEigen(s.bodies[b].state.position);
        const Vector3d ang = arm.cross(dir);
        const int dof = s.bodies[b].dof;
        for (int q = 0; q < 3; ++q) {
          d_entries.emplace_back(dof + q, 3 * i + k, sign * dir(q));
          d_entries.emplace_back(dof + 3 + q, 3 * i + k, sign * ang(q));
        }
      }
    }
  }
}

// D and M^-1 as sparse matrices, and the problem (dense N up to Settings::dense_contact_limit
// contacts, matrix-free above) in c.s.problem, with the compliance cfm / h on N's diagonal.
void problemStage(StepContext& c) {
  WorldState& s = c.s;
  const Settings& cfg = c.cfg;
  const int nc = c.nc, ndof = c.ndof;
  std::vector<Eigen::Triplet<double>>& d_entries = c.d_entries;
  std::vector<Eigen::Triplet<double>>& m_entries = c.m_entries;
  c.d = ccp::SparseMatrix(ndof, 3 * nc);
  c.d.setFromTriplets(d_entries.begin(), d_entries.end());
  m_entries.reserve(static_cast<std::size_t>(ndof) * 3);
  for (std::size_t k = 0; k < s.bodies.size(); ++k) {
    const WorldState::Body& b = s.bodies[k];
    if (b.kinematic) continue;
    for (int q = 0; q < 3; ++q) m_entries.emplace_back(b.dof + q, b.dof + q, 1.0 / b.mass);
    for (int p = 0; p < 3; ++p) {
      for (int q = 0; q < 3; ++q) {
        m_entries.emplace_back(b.dof + 3 + p, b.dof + 3 + q, c.inv_inertia_world[k](p, q));
      }
    }
  }
  c.minv = ccp::SparseMatrix(ndof, ndof);
  c.minv.setFromTriplets(m_entries.begin(), m_entries.end());
  const ccp::SparseMatrix& d = c.d;
  const ccp::SparseMatrix& minv = c.minv;

  const double compliance = cfg.cfm / c.h;
  ccp::Problem& problem = s.problem;
  if (nc <= cfg.dense_contact_limit) {
    Eigen::MatrixXd n = Eigen::MatrixXd(d.transpose() * (minv * d));
    n.diagonal().array() += compliance;
    problem = ccp::Problem::makeDense(std::move(n), c.r, c.mu);
  } else {
    // N + c I = [D; sqrt(c) I]^T blkdiag(M^-1, I) [D; sqrt(c) I]: the compliance enters the
    // matrix-free operator as 3 nc virtual unit-mass coordinates, one per contact row.
    const double root = std::sqrt(compliance);
    ccp::SparseMatrix d_aug(ndof + 3 * nc, 3 * nc), minv_aug(ndof + 3 * nc, ndof + 3 * nc);
    for (int k = 0; k < 3 * nc; ++k) {
      d_entries.emplace_back(ndof + k, k, root);
      m_entries.emplace_back(ndof + k, ndof + k, 1.0);
    }
    d_aug.setFromTriplets(d_entries.begin(), d_entries.end());
    minv_aug.setFromTriplets(m_entries.begin(), m_entries.end());
    problem = ccp::Problem::makeMatrixFree(std::move(d_aug), std::move(minv_aug), c.r, c.mu);
  }
}

// The initial impulses: for each contact, the world-frame impulse of the nearest unclaimed
// contact of the same geom pair in the last step within Settings::warm_start_distance, else of
// the pair's contact at the same index in dCollide's list, expressed in the new frame
// (n, t1, t2); zero otherwise. Writes c.gamma.
void warmStartStage(StepContext& c) {
  WorldState& s = c.s;
  c.gamma = Eigen::VectorXd::Zero(3 * c.nc);
  if (!c.cfg.warm_start) return;
  const double limit = c.cfg.warm_start_distance;
  std::map<std::pair<dGeomID, dGeomID>, std::size_t> first_claim;  // offset into warm_claimed
  for (int i = 0; i < c.nc; ++i) {
    const WorldState::RawContact& raw = s.raw[static_cast<std::size_t>(i)];
    auto it = s.warm.find({raw.g1, raw.g2});
    if (it == s.warm.end()) continue;
    const std::vector<WorldState::WarmContact>& last = it->second;
    auto [claim, fresh] = first_claim.try_emplace(it->first, s.warm_claimed.size());
    if (fresh) s.warm_claimed.resize(s.warm_claimed.size() + last.size(), 0);
    std::size_t best = last.size();
    double best_distance = limit;
    for (std::size_t k = 0; k < last.size(); ++k) {
      if (s.warm_claimed[claim->second + k]) continue;
      const double distance = (last[k].position - raw.p).norm();
      if (distance <= best_distance) {
        best_distance = distance;
        best = k;
      }
    }
    if (best == last.size()) {
      // No contact of the pair within the distance (e.g. a part sliding faster than
      // warm_start_distance / h): the one at the same place in dCollide's list, if unclaimed.
      for (std::size_t k = 0; k < last.size(); ++k) {
        if (last[k].index == raw.index && !s.warm_claimed[claim->second + k]) best = k;
      }
    }
    if (best == last.size()) continue;
    s.warm_claimed[claim->second + best] = 1;
    c.gamma.segment<3>(3 * i) =
        c.frames[static_cast<std::size_t>(i)].transpose() * last[best].impulse;
  }
  s.warm_claimed.clear();
}

// Settings::ipm_rounds after an unconverged NSGS solve: the interior-point fixed point and NSGS
// in turn, each from the best iterate so far, until one converges; the lower Coulomb residual
// is kept. The step's time limit (if any) covers all the solves: each gets what is left of it.
void alternateWithIpm(StepContext& c) {
  WorldState& s = c.s;
  const Settings& cfg = c.cfg;
  StepReport& report = c.report;
  ccp::IpmSettings& ipm = s.ipm.settings();
  ipm = cfg.ipm;
  ipm.tolerance = cfg.solver.tolerance;
  ipm.residual_rho = cfg.solver.residual_rho;
  const double limit = cfg.solver.time_limit_s;
  ipm.time_limit_s = limit;
  // One solve from c.gamma; false when the rounds must end (no time left, or a refusal).
  auto attempt = [&](auto& solver) {
    if (limit > 0.0) {
      const double left = limit - report.solve.solve_time_s;
      if (left <= 0.0) return false;
      solver.settings().time_limit_s = left;
    }
    s.trial_gamma = c.gamma;
    const ccp::Result next = solver.solve(s.problem, s.trial_gamma);
    if (next.status == ccp::Status::InvalidInput) {
      report.ipm_not_run = next.message;
      return false;
    }
    const double earlier = report.solve.solve_time_s;
    if (next.status != ccp::Status::NumericalIssue &&
        next.coulomb_distance < report.solve.coulomb_distance) {
      report.solve = next;
      c.gamma = s.trial_gamma;
    }
    report.solve.solve_time_s = earlier + next.solve_time_s;
    return true;
  };
  for (int round = 0; round < cfg.ipm_rounds; ++round) {
    if (!attempt(s.ipm)) return;
    ++report.ipm_rounds;
    if (report.solve.status != ccp::Status::MaxIterations || !attempt(s.nsgs)) return;
    if (report.solve.status != ccp::Status::MaxIterations) return;
  }
}

// The contact solve, its fallback flags and the guard against non-finite impulses. Writes
// c.report.solve, coulomb_fallback, coulomb_residual and c.gamma.
void solveStage(StepContext& c) {
  WorldState& s = c.s;
  const Settings& cfg = c.cfg;
  StepReport& report = c.report;
  Eigen::VectorXd& gamma = c.gamma;
  const bool nsgs =
      cfg.solver.coulomb_outer_iterations > 0 && cfg.coulomb_solver == CoulombSolver::Nsgs;
  if (nsgs) {
    ccp::NsgsSettings& settings = s.nsgs.settings();
    settings = cfg.nsgs;
    settings.tolerance = cfg.solver.tolerance;
    settings.residual_rho = cfg.solver.residual_rho;
    settings.time_limit_s = cfg.solver.time_limit_s;
    settings.warm_start = true;  // gamma is zero without Settings::warm_start
    report.solve = s.nsgs.solve(s.problem, gamma);
    // Alternate with the interior-point fixed point while unconverged: each solver starts from
    // the best iterate so far and the lower Coulomb residual is kept (Settings::ipm_rounds).
    // Where the rounds cannot run, the step says why (StepReport::ipm_not_run).
    if (report.solve.status == ccp::Status::MaxIterations && cfg.ipm_rounds > 0) {
      if (c.nc > cfg.ipm_max_contacts) {
        report.ipm_not_run = std::to_string(c.nc) + " contacts, above ipm_max_contacts = " +
                             std::to_string(cfg.ipm_max_contacts);
      } else {
        alternateWithIpm(c);
      }
    }
    report.coulomb_residual = report.solve.coulomb_distance;
  } else {
    s.solver.settings() = cfg.solver;
    s.solver.settings().coulomb_max_separation =
        std::max(cfg.solver.coulomb_max_separation,
                 detail::kSpuriousSeparationShare * toEigen(cfg.gravity).norm() * c.h);
    report.solve = s.solver.solve(s.problem, gamma);
    // When the true-Coulomb fixed point does not settle, the solver returns its outer iterate
    // with the lowest Coulomb residual, and the step uses it, normals corrected when it
    // separates a pressed contact faster than coulomb_max_separation (solver.cpp). The relaxed
    // CCP is no fallback: it separates every sliding contact at u_n = mu |u_t| (a box on a
    // 10 m/s belt with mu = 0.5 leaves at 5 m/s). A shifted iterate k + 1 separates a sliding
    // contact only by mu (|u_t^(k+1)| - |u_t^(k)|), the change of slip between iterates, and the
    // Coulomb residual (reported) bounds that: with rho = 1 a pressed contact's normal velocity
    // error is at most coulomb_residual (1 + |r|) (m/s).
    report.coulomb_fallback = cfg.solver.coulomb_outer_iterations > 0 &&
                              report.solve.status == ccp::Status::MaxIterations;
    report.coulomb_residual = report.solve.coulomb_distance;
  }
  if (report.solve.status == ccp::Status::InvalidInput) {
    detail::refuse("step: the contact problem was refused: " + report.solve.message);
  }
  if (!gamma.allFinite()) {
    // Not expected (the solver returns its last finite iterate), but never integrated: the
    // non-finite contact blocks apply no impulse and the step's status says so.
    for (int i = 0; i < 3 * c.nc; ++i) {
      if (!std::isfinite(gamma(i))) gamma.segment<3>(3 * (i / 3)).setZero();
    }
    report.solve.status = ccp::Status::NumericalIssue;
    report.solve.message += " (non-finite impulses were dropped)";
  }
}

// Velocities after the impulses (c.v_next), the warm-start store and the contact records
// (c.out, world frame).
void recordStage(StepContext& c) {
  WorldState& s = c.s;
  const ccp::SparseMatrix& d = c.d;
  const Eigen::VectorXd& gamma = c.gamma;
  c.v_next = c.v_free + c.minv * (d * gamma);
  const Eigen::VectorXd u = d.transpose() * c.v_next + (c.r - d.transpose() * c.v_free);

  s.warm.clear();
  for (int i = 0; i < c.nc; ++i) {
    const WorldState::RawContact& raw = s.raw[static_cast<std::size_t>(i)];
    const Matrix3d& f = c.frames[static_cast<std::size_t>(i)];
    s.warm[{raw.g1, raw.g2}].push_back(
        {raw.p, f.col(0) * gamma(3 * i) + f.col(1) * gamma(3 * i + 1) + f.col(2) * gamma(3 * i + 2),
         raw.index});
    ContactImpulse& ci = c.out[static_cast<std::size_t>(i)];
    ci.g1 = raw.g1;
    ci.g2 = raw.g2;
    ci.body1 = raw.a;
    ci.body2 = raw.b;
    ci.position = toVec3(raw.p);
    ci.normal = toVec3(raw.n);
    ci.depth = raw.depth;
    ci.normal_impulse = gamma(3 * i);
    ci.tangential_impulse = toVec3(gamma(3 * i + 1) * f.col(1) + gamma(3 * i + 2) * f.col(2));
    ci.slip = toVec3(u(3 * i + 1) * f.col(1) + u(3 * i + 2) * f.col(2));
    ci.normal_velocity = u(3 * i);
  }
}

}  // namespace rheofeed::reference
