// SPDX-License-Identifier: MIT
//
// Primal-dual interior-point method for the convex cone problem with frozen normal offsets, and
// De Saxce's fixed point around it (ipm.hpp).
//
// In the variables x_i = (mu_i gamma_n, gamma_t), i.e. gamma = S x with S_i = diag(1 / mu_i, 1,
// 1), every friction cone becomes the Lorentz cone L = {||x_t|| <= x_0}, which is self-dual. With P
// = S N S and c = S (r + s e_n) the problem is min 1/2 x'Px + c'x over L, whose optimality
// conditions are P x + c = z, x, z in L, x o z = 0 (o: the Jordan product of L, x o z = (x'z, x_0
// z_t + z_0 x_t)); z_i = S_i (u_i + s_i e_n) is the scaled modified velocity. Each iteration
// linearises them around the Nesterov-Todd scaling point (W z = W^-1 x = lambda) and takes
// Mehrotra's predictor-corrector step; the Newton system is
//     (P + W^-2) dx = -(P x + c - z) + W^-1 (lambda \ r_c),   dz = W^-1 (lambda \ r_c - W^-1 dx).

#include "rheofeed/ccp/ipm.hpp"

#include "rheofeed/ccp/cone.hpp"
#include "solver_internal.hpp"

#include <Eigen/Cholesky>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace rheofeed::ccp {

namespace {

// Stop an interior-point solve when its step is shorter than this (no progress possible).
constexpr double kStallStep = 1e-12;
// Share of the distance to the cone's boundary an iterate may move (keeps it interior).
constexpr double kStepToBoundary = 0.99;
// Warm restart of a convex solve: both iterates are moved this share of their mean size into
// the cones' interior along the axis e = (1, 0, 0).
constexpr double kRestartShare = 1e-2;
// Halvings of a step that rounding pushed out of a cone before the solve gives up.
constexpr int kMaxHalvings = 30;

// x' J y with J = diag(1, -1, -1).
double jdot(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
}

// Jordan product of the Lorentz cone.
Eigen::Vector3d jordan(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return {a.dot(b), a[0] * b[1] + b[0] * a[1], a[0] * b[2] + b[0] * a[2]};
}

// y with a o y = b, for a in the cone's interior.
Eigen::Vector3d jordanSolve(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double y0 = (a[0] * b[0] - a[1] * b[1] - a[2] * b[2]) / jdot(a, a);
  return {y0, (b[1] - a[1] * y0) / a[0], (b[2] - a[2] * y0) / a[0]};
}

// Largest alpha >= 0 with x + alpha d in the cone, for x interior (infinity when unbounded).
double stepToBoundary(const Eigen::Vector3d& x, const Eigen::Vector3d& d) {
  const double a = jdot(d, d), b = 2.0 * jdot(x, d), c = jdot(x, x);
  double alpha = d[0] < 0.0 ? -x[0] / d[0] : std::numeric_limits<double>::infinity();
  const double disc = b * b - 4.0 * a * c;
  if (std::abs(a) <= 1e-300 * (b * b + c)) {
    if (b < 0.0) alpha = std::min(alpha, -c / b);
  } else if (disc >= 0.0) {
    const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
    for (double root : {q / a, c / q}) {
      if (root > 0.0) alpha = std::min(alpha, root);
    }
  }
  return alpha;
}

// Nesterov-Todd scaling of one cone pair (x, z interior): W symmetric, W z = W^-1 x = lambda.
struct NtScaling {
  Eigen::Matrix3d w, w_inv;
  Eigen::Vector3d lambda;
};

NtScaling ntScaling(const Eigen::Vector3d& x, const Eigen::Vector3d& z) {
  const Eigen::Vector3d j(1.0, -1.0, -1.0);
  const double xn = std::sqrt(jdot(x, x)), zn = std::sqrt(jdot(z, z));
  const Eigen::Vector3d xb = x / xn, zb = z / zn;
  const Eigen::Vector3d wb = (xb + j.cwiseProduct(zb)) / std::sqrt(2.0 * (1.0 + xb.dot(zb)));
  const Eigen::Vector3d v = (wb + Eigen::Vector3d::UnitX()) / std::sqrt(2.0 * (wb[0] + 1.0));
  const double beta = std::sqrt(xn / zn);
  const Eigen::Matrix3d jm = j.asDiagonal();
  NtScaling s;
  s.w = beta * (2.0 * v * v.transpose() - jm);
  s.w_inv = (2.0 * jm * v * v.transpose() * jm - jm) / beta;
  s.lambda = s.w * z;
  return s;
}

bool interior(const Eigen::Vector3d& x) {
  return x[0] > 0.0 && jdot(x, x) > 0.0;
}

}  // namespace

std::string IpmSettings::validate() const {
  if (max_iterations < 1) return detail::format("max_iterations = %g must be >= 1", max_iterations);
  if (!(inner_tolerance_share > 0.0 && inner_tolerance_share <= 1.0)) {
    return detail::format("inner_tolerance_share = %g must be in (0, 1]", inner_tolerance_share);
  }
  if (max_outer_iterations < 1) {
    return detail::format("max_outer_iterations = %g must be >= 1", max_outer_iterations);
  }
  return detail::checkStopping(tolerance, residual_rho, time_limit_s);
}

struct IpmSolver::Workspace {
  detail::Workspace base;  // lambda (residual scales), u, map, dof_a / dof_b
  Eigen::VectorXd scale;   // S as a vector: (1 / mu, 1, 1) per contact
  Eigen::VectorXd x, z, gamma, r_shifted, rd, dx, dz, rc, d, rhs, y, hy, sy, best, shift;
  std::vector<NtScaling> nt;
  // Dense N.
  Eigen::MatrixXd p;  // S N S
  Eigen::MatrixXd h;
  Eigen::LLT<Eigen::MatrixXd> llt;
  // Matrix-free N = D^T M^-1 D: B = L^T D S with M^-1 = L L^T, and the quasi-definite KKT matrix
  // [Q, B^T; B, -I] (lower triangle) with Q = W^-2.
  SparseMatrix b;
  SparseMatrix kkt;
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower> ldlt;
  Eigen::VectorXd kkt_rhs, kkt_sol;
  bool analysed = false;
};

IpmSolver::IpmSolver() = default;
IpmSolver::IpmSolver(const IpmSettings& settings) : settings_(settings) {}
IpmSolver::~IpmSolver() = default;
IpmSolver::IpmSolver(IpmSolver&&) noexcept = default;
IpmSolver& IpmSolver::operator=(IpmSolver&&) noexcept = default;

namespace {

// Why a problem cannot be solved here (empty when it can).
std::string refusal(const Problem& problem, const IpmSettings& settings) {
  if (std::string bad = settings.validate(); !bad.empty()) return "invalid IPM settings: " + bad;
  if (std::string bad = problem.validate(); !bad.empty()) return "invalid problem: " + bad;
  for (Eigen::Index i = 0; i < problem.numContacts(); ++i) {
    if (!(problem.mu[i] > 0.0)) {
      return "contact " + std::to_string(i) + " has mu = " + detail::format("%g", problem.mu[i]) +
             "; the interior-point method needs mu > 0 at every contact";
    }
  }
  return {};
}

// A result that ends a solve before it starts (refused input, no factorisation).
Result stopped(Status status, std::string message, const detail::Deadline& deadline) {
  Result result;
  result.status = status;
  result.message = std::move(message);
  result.solve_time_s = deadline.elapsed();
  return result;
}

// Fills result's measures for the returned gamma (u = N gamma + r) and its time.
void finish(const Problem& problem, const Eigen::VectorXd& gamma, double rho,
            const detail::Deadline& deadline, detail::Workspace& ws, Result& result) {
  ws.u.resize(problem.size());
  detail::multiplyDelassus(problem, gamma, ws.u, ws);
  ws.u += problem.r;
  detail::computeMeasures(gamma, ws.u, problem.r, problem.mu, rho, ws, result);
  result.solve_time_s = deadline.elapsed();
}

}  // namespace

// The solver's internals, one per solve call.
struct IpmRun {
  const Problem& problem;
  const IpmSettings& settings;
  IpmSolver::Workspace& w;
  const detail::Deadline& deadline;
  Eigen::Index nc;

  // Allocates and precomputes S, P (dense) or B (matrix-free); resets the iterate.
  bool prepare(std::string& message) {
    w.base.resize(nc, problem.numDofs());
    detail::computeContactScales(problem, w.base);
    const Eigen::Index n = problem.size();
    w.scale.resize(n);
    for (Eigen::Index i = 0; i < nc; ++i) w.scale.segment<3>(3 * i) << 1.0 / problem.mu[i], 1, 1;
    for (Eigen::VectorXd* v : {&w.x, &w.z, &w.gamma, &w.r_shifted, &w.rd, &w.dx, &w.dz, &w.rc, &w.d,
                               &w.rhs, &w.y, &w.hy, &w.sy, &w.best})
      v->resize(n);
    w.nt.resize(static_cast<std::size_t>(nc));
    w.analysed = false;
    if (problem.form == DelassusForm::Dense) {
      w.p = w.scale.asDiagonal() * problem.delassus * w.scale.asDiagonal();
      w.p = 0.5 * (w.p + w.p.transpose()).eval();
      return true;
    }
    Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower, Eigen::NaturalOrdering<int>> chol(
        problem.minv);
    if (chol.info() != Eigen::Success) {
      message = "the inverse mass matrix has no Cholesky factor";
      return false;
    }
    const SparseMatrix lt = SparseMatrix(chol.matrixL()).transpose();
    w.b = (lt * problem.d) * w.scale.asDiagonal();
    w.b.makeCompressed();
    return true;
  }

  // x and z on the cones' axes at the problem's scale.
  void start() {
    const double lambda = w.base.lambda.mean();
    const double speed = problem.r.norm() / std::sqrt(double(nc));
    const double g0 = speed > 0.0 ? speed / lambda : 1.0;
    const double z0 = speed > 0.0 ? speed : lambda;
    w.x.setZero();
    w.z.setZero();
    for (Eigen::Index i = 0; i < nc; ++i) {
      w.x[3 * i] = g0;
      w.z[3 * i] = z0;
    }
  }

  // Steps a previous solution back into the interior (warm start of the next convex solve).
  void restart() {
    const double dx = kRestartShare * w.x.norm() / std::sqrt(double(nc));
    const double dz = kRestartShare * w.z.norm() / std::sqrt(double(nc));
    for (Eigen::Index i = 0; i < nc; ++i) {
      w.x[3 * i] += dx;
      w.z[3 * i] += dz;
    }
  }

  // w.base.u = N gamma + r (m/s).
  void velocity(const Eigen::VectorXd& gamma, const Eigen::VectorXd& r) {
    detail::multiplyDelassus(problem, gamma, w.base.u, w.base);
    w.base.u += r;
  }

  // De Saxce's shift s_i = mu_i ||u_t,i|| of the velocities in w.base.u.
  void updateShift() {
    for (Eigen::Index i = 0; i < nc; ++i) {
      w.shift[i] = problem.mu[i] * detail::tangentialNorm(w.base.u.segment<3>(3 * i));
    }
  }

  // w.hy = (P + W^-2) y.
  void multiplyNewton(const Eigen::VectorXd& y) {
    w.sy = w.scale.cwiseProduct(y);  // not w.gamma: that is S x, which the caller reads
    detail::multiplyDelassus(problem, w.sy, w.hy, w.base);
    w.hy = w.scale.cwiseProduct(w.hy);
    for (Eigen::Index i = 0; i < nc; ++i) {
      const Eigen::Matrix3d& wi = w.nt[static_cast<std::size_t>(i)].w_inv;
      w.hy.segment<3>(3 * i) += wi * (wi * y.segment<3>(3 * i));
    }
  }

  bool factorize() {
    if (problem.form == DelassusForm::Dense) {
      w.h = w.p;
      for (Eigen::Index i = 0; i < nc; ++i) {
        const Eigen::Matrix3d& wi = w.nt[static_cast<std::size_t>(i)].w_inv;
        w.h.block<3, 3>(3 * i, 3 * i) += wi * wi;
      }
      w.llt.compute(w.h);
      // P is only semidefinite (rank-deficient contact sets) and W^-2 can vanish in places near
      // the solution: when rounding makes the sum lose definiteness, a diagonal shift of a few
      // ulps of its largest entry restores it (the refinement step corrects the solution).
      const double largest = w.h.diagonal().cwiseAbs().maxCoeff();
      for (double shift = 1e-14; w.llt.info() != Eigen::Success && shift < 1e-6; shift *= 100) {
        w.h.diagonal().array() += shift * largest;
        w.llt.compute(w.h);
      }
      return w.llt.info() == Eigen::Success;
    }
    const Eigen::Index n = problem.size(), m = w.b.rows();
    w.triplets.clear();
    w.triplets.reserve(static_cast<std::size_t>(6 * nc + w.b.nonZeros() + m));
    for (Eigen::Index i = 0; i < nc; ++i) {
      const Eigen::Matrix3d& wi = w.nt[static_cast<std::size_t>(i)].w_inv;
      const Eigen::Matrix3d q = wi * wi;
      for (int a = 0; a < 3; ++a) {
        for (int c = 0; c <= a; ++c) {
          w.triplets.emplace_back(int(3 * i + a), int(3 * i + c), 0.5 * (q(a, c) + q(c, a)));
        }
      }
    }
    for (int col = 0; col < w.b.outerSize(); ++col) {
      for (SparseMatrix::InnerIterator it(w.b, col); it; ++it) {
        w.triplets.emplace_back(int(n + it.row()), col, it.value());
      }
    }
    for (Eigen::Index k = 0; k < m; ++k) w.triplets.emplace_back(int(n + k), int(n + k), -1.0);
    w.kkt.resize(n + m, n + m);
    w.kkt.setFromTriplets(w.triplets.begin(), w.triplets.end());
    if (!w.analysed) {
      w.ldlt.analyzePattern(w.kkt);
      w.analysed = true;
    }
    w.ldlt.factorize(w.kkt);
    // As for the dense form: a vanishing block of Q can round a pivot to zero; shift Q's
    // diagonal by a few ulps of its largest entry (the refinement step corrects the solution).
    double largest = 0.0;
    for (Eigen::Index k = 0; k < n; ++k) largest = std::max(largest, std::abs(w.kkt.coeff(k, k)));
    for (double shift = 1e-14; w.ldlt.info() != Eigen::Success && shift < 1e-6; shift *= 100) {
      for (Eigen::Index k = 0; k < n; ++k) w.kkt.coeffRef(k, k) += shift * largest;
      w.ldlt.factorize(w.kkt);
    }
    return w.ldlt.info() == Eigen::Success;
  }

  // w.y = (P + W^-2)^-1 rhs, with one step of iterative refinement.
  void solveNewton(const Eigen::VectorXd& rhs) {
    auto once = [&](const Eigen::VectorXd& b, Eigen::VectorXd& out) {
      if (problem.form == DelassusForm::Dense) {
        out = w.llt.solve(b);
        return;
      }
      const Eigen::Index n = problem.size();
      w.kkt_rhs.setZero(n + w.b.rows());
      w.kkt_rhs.head(n) = b;
      w.kkt_sol = w.ldlt.solve(w.kkt_rhs);
      out = w.kkt_sol.head(n);
    };
    once(rhs, w.y);
    multiplyNewton(w.y);
    const Eigen::VectorXd correction_rhs = rhs - w.hy;
    Eigen::VectorXd correction;
    once(correction_rhs, correction);
    w.y += correction;
  }

  // dx, dz for the complementarity target rc (Newton system of the file comment).
  void direction() {
    for (Eigen::Index i = 0; i < nc; ++i) {
      const NtScaling& s = w.nt[static_cast<std::size_t>(i)];
      w.d.segment<3>(3 * i) = jordanSolve(s.lambda, w.rc.segment<3>(3 * i));
      w.rhs.segment<3>(3 * i) = -w.rd.segment<3>(3 * i) + s.w_inv * w.d.segment<3>(3 * i);
    }
    solveNewton(w.rhs);
    w.dx = w.y;
    for (Eigen::Index i = 0; i < nc; ++i) {
      const NtScaling& s = w.nt[static_cast<std::size_t>(i)];
      w.dz.segment<3>(3 * i) = s.w_inv * (w.d.segment<3>(3 * i) - s.w_inv * w.dx.segment<3>(3 * i));
    }
  }

  double maxStep() const {
    double alpha = std::numeric_limits<double>::infinity();
    for (Eigen::Index i = 0; i < nc; ++i) {
      alpha = std::min({alpha, stepToBoundary(w.x.segment<3>(3 * i), w.dx.segment<3>(3 * i)),
                        stepToBoundary(w.z.segment<3>(3 * i), w.dz.segment<3>(3 * i))});
    }
    return alpha;
  }

  // Convex residual of the current iterate with offsets w.shift (also leaves w.gamma, w.base.u).
  double convexResidual() {
    w.gamma = w.scale.cwiseProduct(w.x);
    velocity(w.gamma, w.r_shifted);
    return detail::relativeResidual(w.gamma, w.base.u, w.r_shifted, problem.mu,
                                    settings.residual_rho, false, w.base);
  }

  // One convex solve with offsets w.shift to `tolerance`. Returns its outcome.
  detail::InnerOutcome convexSolve(double tolerance) {
    detail::InnerOutcome out;
    w.r_shifted = problem.r;
    for (Eigen::Index i = 0; i < nc; ++i) w.r_shifted[3 * i] += w.shift[i];
    out.status = Status::MaxIterations;
    for (;;) {
      out.residual = convexResidual();
      if (!std::isfinite(out.residual) || !w.x.allFinite() || !w.z.allFinite()) {
        out.status = Status::NumericalIssue;
        out.issue = "non-finite interior-point iterate";
        return out;
      }
      if (out.residual <= tolerance) {
        out.status = Status::Converged;
        return out;
      }
      if (out.iterations >= settings.max_iterations) return out;
      if (deadline.expired()) {
        out.timed_out = true;
        return out;
      }
      ++out.iterations;
      // w.base.u = N gamma + r + s e_n: the dual residual in x-space is S u - z.
      w.rd = w.scale.cwiseProduct(w.base.u) - w.z;
      const double gap = w.x.dot(w.z) / double(nc);
      for (Eigen::Index i = 0; i < nc; ++i) {
        w.nt[static_cast<std::size_t>(i)] = ntScaling(w.x.segment<3>(3 * i), w.z.segment<3>(3 * i));
      }
      if (!factorize()) {
        out.status = Status::NumericalIssue;
        out.issue = "the interior-point Newton system could not be factorised";
        return out;
      }
      for (Eigen::Index i = 0; i < nc; ++i) {
        const Eigen::Vector3d& l = w.nt[static_cast<std::size_t>(i)].lambda;
        w.rc.segment<3>(3 * i) = -jordan(l, l);
      }
      direction();  // affine predictor
      const double affine = std::min(1.0, maxStep());
      const double sigma = std::pow(
          std::max(0.0, (w.x + affine * w.dx).dot(w.z + affine * w.dz) / double(nc) / gap), 3);
      for (Eigen::Index i = 0; i < nc; ++i) {
        const NtScaling& s = w.nt[static_cast<std::size_t>(i)];
        const Eigen::Vector3d dxs = s.w_inv * w.dx.segment<3>(3 * i);
        const Eigen::Vector3d dzs = s.w * w.dz.segment<3>(3 * i);
        w.rc.segment<3>(3 * i) += sigma * gap * Eigen::Vector3d::UnitX() - jordan(dxs, dzs);
      }
      direction();  // Mehrotra corrector
      // Near the solution the iterates approach the cones' boundaries and the test x_0^2 >
      // ||x_t||^2 rounds: a step the boundary computation allows can still leave a cone by an
      // ulp. It is shortened then, and when no share of it stays interior the solve ends with
      // the current iterate (MaxIterations).
      double alpha = std::min(1.0, kStepToBoundary * maxStep());
      bool moved = false;
      for (int halving = 0; halving < kMaxHalvings && alpha > kStallStep; ++halving) {
        w.y = w.x + alpha * w.dx;
        w.hy = w.z + alpha * w.dz;
        bool inside = true;
        for (Eigen::Index i = 0; i < nc && inside; ++i) {
          inside = interior(w.y.segment<3>(3 * i)) && interior(w.hy.segment<3>(3 * i));
        }
        if (inside) {
          w.x = w.y;
          w.z = w.hy;
          moved = true;
          break;
        }
        alpha *= 0.5;
      }
      if (!moved) return out;  // no progress: MaxIterations with this iterate
    }
  }
};

Result IpmSolver::solveConvex(const Problem& problem, const Eigen::VectorXd& shift,
                              Eigen::VectorXd& gamma) {
  const detail::Deadline deadline(settings_.time_limit_s);
  std::string message = refusal(problem, settings_);
  if (message.empty() && (shift.size() != problem.numContacts() || !shift.allFinite() ||
                          (shift.size() > 0 && shift.minCoeff() < 0.0))) {
    message =
        "shift must hold " + std::to_string(problem.numContacts()) + " finite values >= 0 (m/s)";
  }
  if (!message.empty()) return stopped(Status::InvalidInput, std::move(message), deadline);
  if (!workspace_) workspace_ = std::make_unique<Workspace>();
  Workspace& w = *workspace_;
  IpmRun run{problem, settings_, w, deadline, problem.numContacts()};
  gamma.setZero(problem.size());
  Result result;
  if (run.nc > 0) {
    if (!run.prepare(message)) return stopped(Status::NumericalIssue, message, deadline);
    w.shift = shift;
    run.start();
    const detail::InnerOutcome out = run.convexSolve(settings_.tolerance);
    result.status = out.status;
    result.iterations = out.iterations;
    if (out.issue) result.message = out.issue;
    gamma = w.scale.cwiseProduct(w.x);
    result.residual = out.residual;
  } else {
    result.status = Status::Converged;
    w.base.resize(0, problem.numDofs());
    result.residual = 0.0;
  }
  const double residual = result.residual;
  finish(problem, gamma, settings_.residual_rho, deadline, w.base, result);
  result.residual = residual;
  return result;
}

Result IpmSolver::solve(const Problem& problem, Eigen::VectorXd& gamma) {
  const detail::Deadline deadline(settings_.time_limit_s);
  std::string message = refusal(problem, settings_);
  if (!message.empty()) return stopped(Status::InvalidInput, std::move(message), deadline);
  Result result;
  if (!workspace_) workspace_ = std::make_unique<Workspace>();
  Workspace& w = *workspace_;
  const Eigen::Index nc = problem.numContacts();
  IpmRun run{problem, settings_, w, deadline, nc};
  const bool warm = settings_.warm_start && gamma.size() == problem.size() && gamma.allFinite();
  if (!warm) gamma.setZero(problem.size());
  if (nc == 0) {
    w.base.resize(0, problem.numDofs());
    result.status = Status::Converged;
  } else if (!run.prepare(message)) {
    result.status = Status::NumericalIssue;
    result.message = message;
  } else {
    detail::projectOntoCones(gamma, problem.mu);
    w.shift.setZero(nc);
    if (warm) {
      run.velocity(gamma, problem.r);
      run.updateShift();
    }
    w.best = gamma;
    double best = std::numeric_limits<double>::infinity();
    result.status = Status::MaxIterations;
    run.start();
    for (int k = 0; k < settings_.max_outer_iterations; ++k) {
      if (k > 0) run.restart();
      const detail::InnerOutcome out =
          run.convexSolve(settings_.inner_tolerance_share * settings_.tolerance);
      result.iterations += out.iterations;
      result.outer_iterations = k + 1;
      if (out.status == Status::NumericalIssue) {
        if (!std::isfinite(best)) result.status = Status::NumericalIssue;
        result.message = out.issue;
        break;
      }
      // w.gamma is S x; the Coulomb residual of it with De Saxce's velocity.
      run.velocity(w.gamma, problem.r);
      const double coulomb = detail::relativeResidual(w.gamma, w.base.u, problem.r, problem.mu,
                                                      settings_.residual_rho, true, w.base);
      if (coulomb < best) {
        best = coulomb;
        w.best = w.gamma;
      }
      if (coulomb <= settings_.tolerance) {
        result.status = Status::Converged;
        break;
      }
      if (out.timed_out || deadline.expired()) break;
      run.updateShift();
    }
    gamma = w.best;
  }
  finish(problem, gamma, settings_.residual_rho, deadline, w.base, result);
  result.residual = result.coulomb_distance;
  return result;
}

}  // namespace rheofeed::ccp
