// SPDX-License-Identifier: MIT
//
// Global semismooth Newton steps on the Alart-Curnier function (global_newton.hpp), after Alart
// & Curnier (CMAME 1991) and the global Newton solvers compared by Acary, Bremond & Huber
// (INRIA RR-9118, 2018; Siconos' fc3d_nonsmooth_Newton_AlartCurnier).
//
// Per contact i, with u = N gamma + r, the function of local_coulomb.cpp:
//     a = g_n - rho_n u_n,  b = g_t - rho_t u_t,  R = mu max(a, 0)
//     Phi_n = g_n - max(a, 0)
//     Phi_t = g_t - Pi_{D(R)}(b)
// (its zeros are exactly the Coulomb solutions). One element of its generalised Jacobian is
// dPhi_i = B_i dg_i + A_i du_i with, for the normal row, (B, A) = (0, rho_n e_n^T) when a > 0
// and (e_n^T, 0) otherwise, and for the tangential rows
//     inside the disk (||b|| <= R): B_t = 0,  A_t = rho_t [0 I]
//     outside:  B_t = [-mu [a > 0] bhat,  I - (R/||b||) T],  A_t = [mu [a > 0] rho_n bhat,
//               (R/||b||) rho_t T],  bhat = b / ||b||, T = I - bhat bhat^T.
// With du = N dg the Newton system is (B + A N) d = -Phi, non-symmetric, solved by Eigen's
// SparseLU (COLAMD ordering). For a matrix-free problem, N = D^T M^-1 D is not formed: N couples
// every two contacts on one body (a part in a pile touches a dozen), and its factors fill in
// with the pile. The system is solved augmented instead, with w = M^-1 D d:
//     [ B          A D^T ] [d]   [-Phi]
//     [ -M^-1 D    I     ] [w] = [ 0  ]
// whose pattern is D's (each contact row touches its two bodies). Every contact is solved with
// all the others at once, so the impulses of coplanar contacts (a box's four corners, rank
// deficient up to the compliance) and of statically indeterminate piles are distributed in one
// step, where Gauss-Seidel moves them only at the compliance's pace. Globalisation: a step
// length limit and the best iterate by the Coulomb residual (globalNewton's comments).

#include "global_newton.hpp"

#include "rheofeed/ccp/cone.hpp"
#include "solver_internal.hpp"

#include <Eigen/SparseLU>

#include <cmath>
#include <vector>

namespace rheofeed::ccp::detail {

namespace {

// Phi of every contact for impulses g and velocities u; when `a_blocks` and `b_blocks` are
// given, the Jacobian blocks A_i and B_i too.
void alartCurnier(const Problem& problem, const GlobalNewtonWorkspace& ws, const Eigen::VectorXd& g,
                  const Eigen::VectorXd& u, Eigen::VectorXd& phi,
                  std::vector<Eigen::Matrix3d>* a_blocks, std::vector<Eigen::Matrix3d>* b_blocks) {
  const Eigen::Index nc = problem.numContacts();
  phi.resize(3 * nc);
  for (Eigen::Index i = 0; i < nc; ++i) {
    const double mu = problem.mu[i];
    const double rho_n = ws.rho_n[i], rho_t = ws.rho_t[i];
    const Eigen::Vector3d gi = g.segment<3>(3 * i), ui = u.segment<3>(3 * i);
    const double a = gi[0] - rho_n * ui[0];
    const bool pressed = a > 0.0;
    const double radius = mu * (pressed ? a : 0.0);
    const Eigen::Vector2d b = gi.tail<2>() - rho_t * ui.tail<2>();
    const double nb = b.norm();
    const bool inside = nb <= radius;
    phi[3 * i] = gi[0] - (pressed ? a : 0.0);
    phi.segment<2>(3 * i + 1) = gi.tail<2>() - (inside ? b : Eigen::Vector2d(radius * b / nb));
    if (a_blocks == nullptr) continue;
    Eigen::Matrix3d& am = (*a_blocks)[static_cast<std::size_t>(i)];
    Eigen::Matrix3d& bm = (*b_blocks)[static_cast<std::size_t>(i)];
    am.setZero();
    bm.setZero();
    if (pressed) {
      am(0, 0) = rho_n;
    } else {
      bm(0, 0) = 1.0;
    }
    if (inside) {
      am(1, 1) = rho_t;
      am(2, 2) = rho_t;
    } else {
      const Eigen::Vector2d unit = b / nb;
      const Eigen::Matrix2d tangent = Eigen::Matrix2d::Identity() - unit * unit.transpose();
      const double ratio = radius / nb;
      if (pressed) {
        bm.block<2, 1>(1, 0) = -mu * unit;
        am.block<2, 1>(1, 0) = mu * rho_n * unit;
      }
      bm.block<2, 2>(1, 1) = Eigen::Matrix2d::Identity() - ratio * tangent;
      am.block<2, 2>(1, 1) = ratio * rho_t * tangent;
    }
  }
}

}  // namespace

void GlobalNewtonWorkspace::prepare(const Problem& problem) {
  if (problem.form == DelassusForm::Dense) {
    n = problem.delassus.sparseView();
    n.makeCompressed();
  } else {
    minv_d = problem.minv * problem.d;
    minv_d.makeCompressed();
  }
  const Eigen::Index nc = problem.numContacts();
  rho_n.resize(nc);
  rho_t.resize(nc);
  for (Eigen::Index i = 0; i < nc; ++i) {
    const Eigen::Matrix3d w = problem.diagonalBlock(i);
    const Eigen::Matrix2d t = w.bottomRightCorner<2, 2>();
    const double mean = 0.5 * (t(0, 0) + t(1, 1)), gap = 0.5 * (t(0, 0) - t(1, 1));
    const double largest = mean + std::sqrt(gap * gap + t(0, 1) * t(1, 0));
    rho_n[i] = 1.0 / w(0, 0);
    rho_t[i] = 1.0 / largest;
  }
  prepared = true;
}

void GlobalNewtonWorkspace::multiplyN(const Problem& problem, const Eigen::VectorXd& g,
                                      Eigen::VectorXd& out) const {
  if (problem.form == DelassusForm::Dense) {
    out.noalias() = n * g;
  } else {
    out.noalias() = problem.d.transpose() * (minv_d * g);
  }
}

double globalNewton(const Problem& problem, const Eigen::VectorXd& gamma, int iterations,
                    double step_limit, double tolerance, double rho, const Deadline& deadline,
                    GlobalNewtonWorkspace& ws, Workspace& base, Eigen::VectorXd& candidate) {
  if (!ws.prepared) ws.prepare(problem);
  const Eigen::Index nc = problem.numContacts();
  const Eigen::Index n = 3 * nc;
  std::vector<Eigen::Matrix3d> a_blocks(static_cast<std::size_t>(nc));
  std::vector<Eigen::Matrix3d> b_blocks(static_cast<std::size_t>(nc));
  std::vector<Eigen::Triplet<double>> entries;
  const bool augmented = problem.form == DelassusForm::MatrixFree;
  const Eigen::Index m = augmented ? problem.numDofs() : 0;
  Eigen::VectorXd g = gamma;
  Eigen::VectorXd u;
  ws.multiplyN(problem, g, u);
  u += problem.r;
  Eigen::VectorXd phi, trial_u, direction, n_direction, rhs, solution;
  Eigen::SparseLU<SparseMatrix, Eigen::COLAMDOrdering<int>> lu;
  const double start = relativeResidual(gamma, u, problem.r, problem.mu, rho, true, base);
  double best = start;
  Eigen::VectorXd projected(n);
  for (int k = 0; k < iterations && !deadline.expired(); ++k) {
    alartCurnier(problem, ws, g, u, phi, &a_blocks, &b_blocks);
    if (phi.squaredNorm() == 0.0) break;
    entries.clear();
    entries.reserve(static_cast<std::size_t>(augmented ? 4 * problem.d.nonZeros() +
                                                             ws.minv_d.nonZeros() + m + 9 * nc
                                                       : 3 * ws.n.nonZeros() + 9 * nc));
    for (Eigen::Index i = 0; i < nc; ++i) {
      const Eigen::Matrix3d& bm = b_blocks[static_cast<std::size_t>(i)];
      for (int p = 0; p < 3; ++p) {
        for (int q = 0; q < 3; ++q) {
          if (bm(p, q) != 0.0) {
            entries.emplace_back(static_cast<int>(3 * i + p), static_cast<int>(3 * i + q),
                                 bm(p, q));
          }
        }
      }
    }
    if (augmented) {
      // Rows of contact i: A_i D_i^T w, with w = M^-1 D d the unknowns after d.
      for (Eigen::Index col = 0; col < n; ++col) {
        const Eigen::Index i = col / 3;
        const int axis = static_cast<int>(col % 3);
        const Eigen::Matrix3d& am = a_blocks[static_cast<std::size_t>(i)];
        for (SparseMatrix::InnerIterator it(problem.d, col); it; ++it) {
          for (int p = 0; p < 3; ++p) {
            if (am(p, axis) != 0.0) {
              entries.emplace_back(static_cast<int>(3 * i + p), static_cast<int>(n + it.row()),
                                   am(p, axis) * it.value());
            }
          }
        }
        for (SparseMatrix::InnerIterator it(ws.minv_d, col); it; ++it) {
          entries.emplace_back(static_cast<int>(n + it.row()), static_cast<int>(col), -it.value());
        }
      }
      for (Eigen::Index row = 0; row < m; ++row) {
        entries.emplace_back(static_cast<int>(n + row), static_cast<int>(n + row), 1.0);
      }
    } else {
      for (Eigen::Index col = 0; col < n; ++col) {
        for (SparseMatrix::InnerIterator it(ws.n, col); it; ++it) {
          const Eigen::Index i = it.row() / 3;
          const int axis = static_cast<int>(it.row() % 3);
          const Eigen::Matrix3d& am = a_blocks[static_cast<std::size_t>(i)];
          for (int p = 0; p < 3; ++p) {
            if (am(p, axis) != 0.0) {
              entries.emplace_back(static_cast<int>(3 * i + p), static_cast<int>(col),
                                   am(p, axis) * it.value());
            }
          }
        }
      }
    }
    SparseMatrix jacobian(n + m, n + m);
    jacobian.setFromTriplets(entries.begin(), entries.end());
    jacobian.makeCompressed();
    lu.compute(jacobian);
    if (lu.info() != Eigen::Success) break;
    rhs.setZero(n + m);
    rhs.head(n) = -phi;
    solution = lu.solve(rhs);
    if (lu.info() != Eigen::Success || !solution.allFinite()) break;
    direction = solution.head(n);
    ws.multiplyN(problem, direction, n_direction);
    // The step is limited to step_limit times the largest impulse: near a solution the
    // Jacobian's null-space directions (coplanar corners, up to the compliance) can ask for
    // internal impulses far beyond the cones; a limited step crosses the kinks of Phi gradually.
    // No line search on ||Phi||: every iterate is judged by the Coulomb residual below and the
    // best kept, which crosses kinks where a monotone merit would stall (measured: steps of
    // 1e-5 on the main demo's piles).
    double t = 1.0;
    const double limit = step_limit * g.lpNorm<Eigen::Infinity>();
    const double largest = direction.lpNorm<Eigen::Infinity>();
    if (limit > 0.0 && largest > limit) t = limit / largest;
    g += t * direction;
    u += t * n_direction;
    // The iterate is judged as the caller will judge it: projected onto the cones, by its
    // Coulomb residual.
    for (Eigen::Index i = 0; i < nc; ++i) {
      projected.segment<3>(3 * i) = projectOntoCone(g.segment<3>(3 * i), problem.mu[i]);
    }
    ws.multiplyN(problem, projected, trial_u);
    trial_u += problem.r;
    const double residual =
        relativeResidual(projected, trial_u, problem.r, problem.mu, rho, true, base);
    if (residual < best) {
      best = residual;
      candidate = projected;
      if (best <= tolerance) break;
    }
  }
  return best < start ? best : -1.0;
}

}  // namespace rheofeed::ccp::detail
