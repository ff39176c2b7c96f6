// SPDX-License-Identifier: MIT
//
// Solver front end: settings and input checks, warm start, the true-Coulomb outer fixed point,
// and the quality measures of the returned impulses. The inner relaxed solvers are in pgs.cpp
// and apgd.cpp.
//
// True Coulomb mode (Acary, Cadoux, Lemarechal & Malick, "A formulation of the linear discrete
// Coulomb friction problem via convex optimization", ZAMM 2011): the Coulomb law is the CCP
// written for De Saxce's modified velocity `u + mu ||u_t|| e_n`. Freezing `s_i = mu_i ||u_t,i||`
// makes it the relaxed CCP with `r_n` replaced by `r_n + s`; iterating `s <- mu ||u_t(gamma(s))||`
// is a fixed point whose limit solves the Coulomb problem (a sliding contact then has u_n = 0
// instead of the relaxation's u_n = mu ||u_t||). Tangential velocities are not changed by the
// shift, so `u_t` can be read from either problem. The loop first tries the relaxed solution
// (s = 0) and keeps the iterate with the lowest Coulomb residual: for a sliding contact of
// iterate k + 1, u_n = mu (||u_t^(k+1)|| - ||u_t^(k)||), so an iterate's spurious separation is
// the change of slip, which the Coulomb residual measures, not the relaxation's mu ||u_t||.
//
// Frozen-friction normal correction (when the fixed point does not settle). The best iterate's
// spurious separation mu (||u_t^(k)|| - ||u_t^(k+1)||) is large exactly where slip collapses
// between iterates (a part going from sliding to sticking, or wedged on a seam: 0.61 m/s
// measured on the helical-ramp scene), and a normal impulse on a separating contact is a
// launch that friction, not any physical normal push, created. Signorini's law (gamma_n >= 0,
// u_n >= 0, gamma_n u_n = 0) excludes it, so when a contact carrying a normal impulse separates
// faster than Settings::coulomb_max_separation, the normals are solved again with the best
// iterate's friction impulses gamma_t frozen: the CCP with mu = 0 and r' = r + N [0; gamma_t],
// a convex normal-only problem (the inner solver, warm-started from the iterate's gamma_n).
// Its solution obeys Signorini for that friction, but a normal impulse that dropped may leave
// ||gamma_t|| > mu gamma_n, so every such friction impulse is shrunk radially onto the cone
// (direction kept) and the normals are solved again. Friction magnitudes only decrease, so the
// rounds converge; they stop when no friction needed shrinking (then Signorini holds with
// friction in the cone). After 10 x coulomb_outer_iterations rounds a contact that still needs
// shrinking loses its friction for the step (counted in Result::friction_dropped_contacts),
// which ends the rounds after at most nc more. The result is in K and no contact is pushed
// apart by its own normal impulse; what friction loses is maximal dissipation at the corrected
// contacts (a sliding contact may brake less than mu gamma_n), which the reported Coulomb
// residual measures. Where the corrected impulses meet the Coulomb tolerance, the solve is
// Converged.

#include "rheofeed/ccp/solver.hpp"

#include "rheofeed/ccp/cone.hpp"
#include "solver_internal.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace rheofeed::ccp {

namespace detail {

void Workspace::resize(Eigen::Index nc, Eigen::Index ndof) {
  const Eigen::Index n = 3 * nc;
  for (Eigen::VectorXd* v : {&u, &r_shifted, &iterate, &n_iterate, &next, &n_next, &y, &n_y, &best,
                             &coulomb_best, &coulomb_start, &friction, &r_normal, &map})
    v->resize(n);
  for (Eigen::VectorXd* v : {&lambda, &eta, &shift, &shift_new, &zero_mu}) v->resize(nc);
  dof_a.resize(ndof);
  dof_b.resize(ndof);
}

void multiplyDelassus(const Problem& problem, const Eigen::VectorXd& x, Eigen::VectorXd& y,
                      Workspace& ws) {
  if (problem.form == DelassusForm::Dense) {
    y.noalias() = problem.delassus * x;
    return;
  }
  // dof_a = D x
  const SparseMatrix& d = problem.d;
  ws.dof_a.setZero();
  for (Eigen::Index col = 0; col < d.outerSize(); ++col) {
    const double xc = x[col];
    if (xc == 0.0) continue;
    for (SparseMatrix::InnerIterator it(d, col); it; ++it) ws.dof_a[it.row()] += it.value() * xc;
  }
  // dof_b = M^-1 dof_a
  const SparseMatrix& minv = problem.minv;
  ws.dof_b.setZero();
  for (Eigen::Index col = 0; col < minv.outerSize(); ++col) {
    const double a = ws.dof_a[col];
    if (a == 0.0) continue;
    for (SparseMatrix::InnerIterator it(minv, col); it; ++it) ws.dof_b[it.row()] += it.value() * a;
  }
  // y = D^T dof_b
  for (Eigen::Index col = 0; col < d.outerSize(); ++col) {
    double sum = 0.0;
    for (SparseMatrix::InnerIterator it(d, col); it; ++it) sum += it.value() * ws.dof_b[it.row()];
    y[col] = sum;
  }
}

void computeContactScales(const Problem& problem, Workspace& ws) {
  for (Eigen::Index i = 0; i < problem.numContacts(); ++i) {
    ws.lambda[i] = problem.diagonalBlock(i).trace() / 3.0;
  }
}

double relativeResidual(const Eigen::VectorXd& gamma, const Eigen::VectorXd& u,
                        const Eigen::VectorXd& r, const Eigen::VectorXd& mu, double rho,
                        bool coulomb, Workspace& ws) {
  for (Eigen::Index i = 0; i < mu.size(); ++i) {
    const Eigen::Vector3d g = gamma.segment<3>(3 * i);
    Eigen::Vector3d velocity = u.segment<3>(3 * i);
    if (coulomb) velocity[0] += mu[i] * std::hypot(velocity[1], velocity[2]);
    // rho / lambda_i is the block step of PGS (kg): impulse and velocity terms of the map then
    // scale alike when N or r is scaled, and dividing by it again gives a velocity.
    const double step = rho / ws.lambda[i];
    ws.map.segment<3>(3 * i) = (g - projectOntoCone(g - step * velocity, mu[i])) / step;
  }
  const double error = safeNorm(ws.map);
  const double scale = std::max(safeNorm(r), safeNorm(u - r));
  if (!std::isfinite(error) || !std::isfinite(scale)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  // scale == 0 means u = 0 and N gamma = 0; with gamma in K the map is then exactly zero.
  if (error == 0.0) return 0.0;
  return scale > 0.0 ? error / scale : std::numeric_limits<double>::infinity();
}

void projectOntoCones(Eigen::VectorXd& gamma, const Eigen::VectorXd& mu) {
  for (Eigen::Index i = 0; i < mu.size(); ++i) {
    gamma.segment<3>(3 * i) = projectOntoCone(gamma.segment<3>(3 * i), mu[i]);
  }
}

// Fills the measures of `result` for impulses gamma with u = N gamma + r (u given).
void computeMeasures(const Eigen::VectorXd& gamma, const Eigen::VectorXd& u,
                     const Eigen::VectorXd& r, const Eigen::VectorXd& mu, double rho, Workspace& ws,
                     Result& result) {
  double dual = 0.0;
  double complementarity = 0.0;
  for (Eigen::Index i = 0; i < mu.size(); ++i) {
    const Eigen::Vector3d g = gamma.segment<3>(3 * i);
    const Eigen::Vector3d ui = u.segment<3>(3 * i);
    dual += projectOntoCone(-ui, mu[i]).squaredNorm();
    complementarity += std::abs(g.dot(ui));
  }
  result.dual_infeasibility = std::sqrt(dual);
  result.complementarity = complementarity;
  // 1/2 g^T N g + r^T g with N g = u - r.
  result.objective = 0.5 * gamma.dot(u + r);
  result.coulomb_distance = relativeResidual(gamma, u, r, mu, rho, true, ws);
}

}  // namespace detail

namespace {

std::string format(const char* fmt, double a, double b = 0.0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, fmt, a, b);
  return std::string(buffer);
}

}  // namespace

const char* toString(Method method) {
  switch (method) {
    case Method::Pgs:
      return "PGS";
    case Method::Apgd:
      return "APGD";
  }
  return "Unknown";
}

const char* toString(Status status) {
  switch (status) {
    case Status::NotRun:
      return "NotRun";
    case Status::Converged:
      return "Converged";
    case Status::MaxIterations:
      return "MaxIterations";
    case Status::NumericalIssue:
      return "NumericalIssue";
    case Status::InvalidInput:
      return "InvalidInput";
  }
  return "Unknown";
}

std::string Settings::validate() const {
  if (method != Method::Pgs && method != Method::Apgd) return "method is not PGS or APGD";
  if (max_iterations < 1) return format("max_iterations = %g must be >= 1", max_iterations);
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance)) {
    return format("tolerance = %g must be finite and >= 0", tolerance);
  }
  if (!(residual_rho > 0.0) || !std::isfinite(residual_rho)) {
    return format("residual_rho = %g must be finite and > 0", residual_rho);
  }
  if (!(omega > 0.0 && omega < 2.0)) return format("omega = %g must be in (0, 2)", omega);
  if (pgs_refresh_interval < 1) {
    return format("pgs_refresh_interval = %g must be >= 1", pgs_refresh_interval);
  }
  if (!(time_limit_s >= 0.0)) return format("time_limit_s = %g must be >= 0", time_limit_s);
  if (coulomb_outer_iterations < 0) {
    return format("coulomb_outer_iterations = %g must be >= 0", coulomb_outer_iterations);
  }
  if (!(coulomb_tolerance >= 0.0) || !std::isfinite(coulomb_tolerance)) {
    return format("coulomb_tolerance = %g must be finite and >= 0", coulomb_tolerance);
  }
  if (!(coulomb_max_separation >= 0.0)) {
    return format("coulomb_max_separation = %g must be >= 0", coulomb_max_separation);
  }
  return {};
}

struct Solver::Workspace : detail::Workspace {};

Solver::Solver() = default;
Solver::Solver(const Settings& settings) : settings_(settings) {}
Solver::~Solver() = default;
Solver::Solver(Solver&&) noexcept = default;
Solver& Solver::operator=(Solver&&) noexcept = default;

namespace {

// One solve's state, shared by its stages (Solver::solve below): the problem, settings and
// workspace, the impulses being solved for, the result being filled and the inner outcome.
struct SolveContext {
  const Problem& problem;
  const Settings& settings;
  const detail::Deadline& deadline;
  Eigen::VectorXd& gamma;
  detail::Workspace& ws;
  Result& result;
  detail::InnerOutcome outcome;

  // One relaxed solve with the free velocity `r` and friction coefficients `mu`.
  detail::InnerOutcome inner(const Eigen::VectorXd& r, const Eigen::VectorXd& mu) {
    return settings.method == Method::Pgs
               ? detail::runPgs(problem, r, mu, settings, deadline, gamma, ws)
               : detail::runApgd(problem, r, mu, settings, deadline, gamma, ws);
  }
  // ws.u = N gamma + r_problem; used for the shift and the final measures.
  void physicalVelocity() {
    detail::multiplyDelassus(problem, gamma, ws.u, ws);
    ws.u += problem.r;
  }
  // s_i = mu_i ||u_t,i|| from ws.u.
  void updateShift(Eigen::VectorXd& shift) const {
    for (Eigen::Index i = 0; i < problem.numContacts(); ++i)
      shift[i] = problem.mu[i] * std::hypot(ws.u[3 * i + 1], ws.u[3 * i + 2]);
  }
  // A non-finite Coulomb residual or shift (overflow of mu ||u_t|| or of N gamma) ends the
  // loop as a numerical issue, never as an iteration limit.
  void numericalIssue(const char* issue) {
    outcome.status = Status::NumericalIssue;
    outcome.issue = issue;
  }
  double coulombResidual() {
    return detail::relativeResidual(gamma, ws.u, problem.r, problem.mu, settings.residual_rho, true,
                                    ws);
  }
};

// Stage 1: settings and problem checks. Empty when usable, else the InvalidInput message.
std::string inputProblem(const Settings& settings, const Problem& problem) {
  if (std::string message = settings.validate(); !message.empty()) {
    return "invalid settings: " + message;
  }
  if (std::string message = problem.validate(); !message.empty()) {
    return "invalid problem: " + message;
  }
  return {};
}

// Stage 2: workspace sizes, contact scales and the initial guess (warm start or zero).
void prepare(SolveContext& c) {
  const Eigen::Index n = c.problem.size();
  c.ws.resize(c.problem.numContacts(), c.problem.numDofs());
  detail::computeContactScales(c.problem, c.ws);
  const bool warm = c.settings.warm_start && c.gamma.size() == n && c.gamma.allFinite();
  if (warm) {
    detail::projectOntoCones(c.gamma, c.problem.mu);
  } else {
    c.gamma.resize(n);
    c.gamma.setZero();
  }
}

// What the outer fixed point of the Coulomb mode ends with.
struct FixedPointEnd {
  bool reached = false;  // a Coulomb solution to the tolerance, or a settled shift
  double best_coulomb = std::numeric_limits<double>::infinity();
  double best_inner_residual = std::numeric_limits<double>::quiet_NaN();
};

// Stage 3b: the true-Coulomb outer fixed point on De Saxce's shift (file comment).
//
// Outer iteration 0 is the relaxed CCP itself (shift 0), from the incoming gamma: where no
// contact slides it already is the Coulomb solution (issue 9: a cold fixed point took 45000
// APGD iterations on a problem whose relaxed solution, 505 iterations, satisfied Coulomb).
// Otherwise the shift iteration starts from the incoming gamma and its shift, as a fixed
// point from the relaxed solution can stall (measured on the rank-deficient Capsules fc3d
// problem: Coulomb residual 2e-8 after 200 outer iterations from the relaxed solution,
// converged from gamma = 0). Every iterate, the relaxed one included, is judged by its own
// Coulomb residual for the problem's r, and the best one is returned when the fixed point
// does not settle.
FixedPointEnd coulombFixedPoint(SolveContext& c) {
  const Problem& problem = c.problem;
  const Settings& settings = c.settings;
  detail::Workspace& ws = c.ws;
  const Eigen::Index nc = problem.numContacts();
  FixedPointEnd end;
  ws.coulomb_start = c.gamma;
  ws.shift.setZero();
  double change = 0.0;
  for (int outer = 0; outer < settings.coulomb_outer_iterations; ++outer) {
    ws.r_shifted = problem.r;
    for (Eigen::Index i = 0; i < nc; ++i) ws.r_shifted[3 * i] += ws.shift[i];
    c.outcome = c.inner(ws.r_shifted, problem.mu);
    c.result.iterations += c.outcome.iterations;
    c.result.outer_iterations = outer + 1;
    if (c.outcome.status == Status::NumericalIssue || c.outcome.timed_out) break;
    c.physicalVelocity();
    const double coulomb = c.coulombResidual();
    if (!std::isfinite(coulomb)) {
      c.numericalIssue(
          "Coulomb mode: non-finite Coulomb residual (impulses or velocities "
          "overflowed)");
      break;
    }
    // The relaxed iterate is returned only as a Coulomb solution (below): as a best-effort
    // answer it would separate every sliding contact at mu ||u_t||, which is what Coulomb
    // mode exists to avoid. (With coulomb_outer_iterations == 1 it is the only iterate.)
    const bool candidate = outer > 0 || settings.coulomb_outer_iterations == 1;
    if (candidate && coulomb < end.best_coulomb) {
      end.best_coulomb = coulomb;
      end.best_inner_residual = c.outcome.residual;
      ws.coulomb_best = c.gamma;
    }
    if (coulomb <= settings.tolerance) {
      end.reached = true;  // a Coulomb solution to the tolerance, however reached
      break;
    }
    if (outer == 0) {
      c.gamma = ws.coulomb_start;
      c.physicalVelocity();
      c.updateShift(ws.shift);
      if (!ws.shift.allFinite()) {
        c.numericalIssue("Coulomb mode: non-finite normal shift mu ||u_t|| (overflow)");
        break;
      }
      continue;
    }
    c.updateShift(ws.shift_new);
    if (!ws.shift_new.allFinite()) {
      c.numericalIssue("Coulomb mode: non-finite normal shift mu ||u_t|| (overflow)");
      break;
    }
    // Dimensionless like the residual: the shift (m/s) relative to the velocity scale
    // max(||r||, ||N gamma||) of the current iterate.
    const double velocity_scale =
        std::max(detail::safeNorm(problem.r), detail::safeNorm(ws.u - problem.r));
    const double shift_change = detail::safeNorm(ws.shift_new - ws.shift);
    change = shift_change == 0.0 ? 0.0 : shift_change / velocity_scale;
    ws.shift.swap(ws.shift_new);
    if (change <= settings.coulomb_tolerance && c.outcome.status == Status::Converged) {
      end.reached = true;
      break;
    }
  }
  return end;
}

// Stage 3c: frozen-friction normal correction of the best iterate (file comment). Returns true
// when the rounds settled and the corrected impulses meet the Coulomb tolerance.
bool frozenFrictionCorrection(SolveContext& c) {
  const Problem& problem = c.problem;
  detail::Workspace& ws = c.ws;
  Eigen::VectorXd& gamma = c.gamma;
  const Eigen::Index nc = problem.numContacts();
  ws.zero_mu.setZero();
  const int shrink_rounds = 10 * c.settings.coulomb_outer_iterations;
  bool settled = false;
  for (int round = 0; !settled; ++round) {
    const bool drop = round >= shrink_rounds;  // past the budget: drop, not shrink
    ws.friction = gamma;
    for (Eigen::Index i = 0; i < nc; ++i) {
      ws.friction[3 * i] = 0.0;
      gamma.segment<2>(3 * i + 1).setZero();
    }
    detail::multiplyDelassus(problem, ws.friction, ws.r_normal, ws);
    ws.r_normal += problem.r;
    const detail::InnerOutcome normal = c.inner(ws.r_normal, ws.zero_mu);
    c.result.iterations += normal.iterations;
    c.result.normal_correction_rounds = round + 1;
    if (normal.status == Status::NumericalIssue || normal.timed_out) {
      c.outcome.status = normal.status;
      c.outcome.timed_out = normal.timed_out;
      c.outcome.issue = normal.issue;
      gamma = ws.coulomb_best;  // the best iterate, uncorrected
      break;
    }
    settled = true;
    for (Eigen::Index i = 0; i < nc; ++i) {
      Eigen::Ref<Eigen::Vector2d> t = ws.friction.segment<2>(3 * i + 1);
      const double limit = problem.mu[i] * gamma[3 * i];
      const double magnitude = t.norm();
      if (magnitude > limit) {
        settled = false;
        if (drop || !(magnitude > 0.0)) {
          t.setZero();
          ++c.result.friction_dropped_contacts;
        } else {
          t *= limit / magnitude;
        }
      }
      gamma.segment<2>(3 * i + 1) = t;
    }
    c.outcome.residual = normal.residual;
  }
  c.result.normal_correction_settled = settled;
  if (!settled) return false;
  // The corrected impulses may satisfy the Coulomb law to the tolerance themselves.
  c.physicalVelocity();
  return c.coulombResidual() <= c.settings.tolerance;
}

// Stage 3 (Coulomb mode): the fixed point, then, when it does not settle, the best iterate with
// its normals corrected where it separates a pressed contact; sets the outcome's status.
void solveCoulomb(SolveContext& c) {
  FixedPointEnd end = coulombFixedPoint(c);
  const bool have_best = end.best_coulomb < std::numeric_limits<double>::infinity();
  if (!end.reached && have_best) {
    c.gamma = c.ws.coulomb_best;
    c.outcome.residual = end.best_inner_residual;
    // The largest normal velocity of a contact that carries a normal impulse: a separation
    // the impulses themselves produce (for a converged solve it is zero up to the tolerance).
    c.physicalVelocity();
    double separation = 0.0;
    for (Eigen::Index i = 0; i < c.problem.numContacts(); ++i) {
      if (c.gamma[3 * i] > 0.0) separation = std::max(separation, c.ws.u[3 * i]);
    }
    c.result.best_iterate_separation = separation;
    if (separation > c.settings.coulomb_max_separation &&
        c.outcome.status != Status::NumericalIssue && !c.outcome.timed_out) {
      if (frozenFrictionCorrection(c)) end.reached = true;
    }
  }
  if (end.reached) c.outcome.status = Status::Converged;
  if (c.outcome.status != Status::NumericalIssue && !c.outcome.timed_out && !end.reached) {
    c.outcome.status = Status::MaxIterations;
    c.result.message = format(
        "Coulomb fixed point not reached after %g outer iterations: returned the best iterate, "
        "Coulomb residual %g",
        c.result.outer_iterations, end.best_coulomb);
  }
}

// Stage 4: status, message and the quality measures of the returned gamma.
void finish(SolveContext& c) {
  Result& result = c.result;
  result.status = c.outcome.status;
  if (c.outcome.status == Status::NumericalIssue && c.outcome.issue != nullptr) {
    result.message = c.outcome.issue;
  } else if (c.outcome.timed_out) {
    result.message = format("time limit of %g s reached", c.deadline.limit());
  }
  c.physicalVelocity();
  detail::computeMeasures(c.gamma, c.ws.u, c.problem.r, c.problem.mu, c.settings.residual_rho, c.ws,
                          result);
  if (c.settings.coulomb_outer_iterations == 0) {
    result.residual = detail::relativeResidual(c.gamma, c.ws.u, c.problem.r, c.problem.mu,
                                               c.settings.residual_rho, false, c.ws);
  } else {
    result.residual = c.outcome.residual;
  }
}

}  // namespace

Result Solver::solve(const Problem& problem, Eigen::VectorXd& gamma) {
  const detail::Deadline deadline(settings_.time_limit_s);
  Result result;
  if (std::string message = inputProblem(settings_, problem); !message.empty()) {
    result.status = Status::InvalidInput;
    result.message = std::move(message);
    result.solve_time_s = deadline.elapsed();
    return result;
  }
  if (!workspace_) workspace_ = std::make_unique<Workspace>();
  SolveContext context{problem, settings_, deadline, gamma, *workspace_, result, {}};
  prepare(context);
  if (problem.size() == 0) {
    context.outcome.status = Status::Converged;
  } else if (settings_.coulomb_outer_iterations == 0) {
    context.outcome = context.inner(problem.r, problem.mu);
    result.iterations = context.outcome.iterations;
  } else {
    solveCoulomb(context);
  }
  finish(context);
  result.solve_time_s = deadline.elapsed();
  return result;
}

}  // namespace rheofeed::ccp
