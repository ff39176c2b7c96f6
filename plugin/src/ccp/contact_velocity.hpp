// SPDX-License-Identifier: MIT
#pragma once

// Contact velocities kept up to date while a Gauss-Seidel method changes one contact's impulse
// at a time (block PGS in pgs.cpp, NSGS in nsgs.cpp). Internal, not installed.
//  - dense N: u = N gamma + r itself, u += N(:, 3i..3i+2) delta_i (three contiguous columns);
//  - matrix free: the generalised velocity w = M^-1 D gamma, w += M^-1 D_i delta_i, and
//    u_i = D_i^T w + r_i (only the sparse columns of the contact's bodies are touched).
// Both expose refresh(gamma) (recompute from scratch), velocity(i) (u_i, m/s),
// applyChange(i, delta) and updateVelocity() (fill ws.u for the residual).

#include "solver_internal.hpp"

#include <Eigen/Core>

namespace rheofeed::ccp::detail {

// Dense N: keeps ws.u = N gamma + r up to date.
class DenseContacts {
 public:
  DenseContacts(const Problem& problem, const Eigen::VectorXd& r, Workspace& ws)
      : n_(problem.delassus), r_(r), u_(ws.u) {}

  void refresh(const Eigen::VectorXd& gamma) {
    u_.noalias() = n_ * gamma;
    u_ += r_;
  }
  Eigen::Vector3d velocity(Eigen::Index i) const { return u_.segment<3>(3 * i); }
  void applyChange(Eigen::Index i, const Eigen::Vector3d& delta) {
    u_ += n_.col(3 * i) * delta[0] + n_.col(3 * i + 1) * delta[1] + n_.col(3 * i + 2) * delta[2];
  }
  // ws.u is already the full contact velocity.
  void updateVelocity() {}

 private:
  const Eigen::MatrixXd& n_;
  const Eigen::VectorXd& r_;
  Eigen::VectorXd& u_;
};

// Matrix-free: keeps w = ws.dof_b = M^-1 D gamma up to date; u_i = D_i^T w + r_i.
class MatrixFreeContacts {
 public:
  MatrixFreeContacts(const Problem& problem, const Eigen::VectorXd& r, Workspace& ws)
      : d_(problem.d), minv_(problem.minv), r_(r), ws_(ws) {}

  void refresh(const Eigen::VectorXd& gamma) {
    ws_.dof_a.setZero();
    for (Eigen::Index col = 0; col < d_.outerSize(); ++col) {
      const double g = gamma[col];
      if (g == 0.0) continue;
      for (SparseMatrix::InnerIterator it(d_, col); it; ++it) ws_.dof_a[it.row()] += it.value() * g;
    }
    ws_.dof_b.setZero();
    for (Eigen::Index col = 0; col < minv_.outerSize(); ++col) {
      const double a = ws_.dof_a[col];
      if (a == 0.0) continue;
      for (SparseMatrix::InnerIterator it(minv_, col); it; ++it) {
        ws_.dof_b[it.row()] += it.value() * a;
      }
    }
  }
  Eigen::Vector3d velocity(Eigen::Index i) const {
    Eigen::Vector3d u;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Index col = 3 * i + k;
      double sum = r_[col];
      for (SparseMatrix::InnerIterator it(d_, col); it; ++it)
        sum += it.value() * ws_.dof_b[it.row()];
      u[k] = sum;
    }
    return u;
  }
  void applyChange(Eigen::Index i, const Eigen::Vector3d& delta) {
    for (int k = 0; k < 3; ++k) {
      if (delta[k] == 0.0) continue;
      for (SparseMatrix::InnerIterator it(d_, 3 * i + k); it; ++it) {
        const double impulse = it.value() * delta[k];  // generalised impulse on dof it.row()
        for (SparseMatrix::InnerIterator m(minv_, it.row()); m; ++m) {
          ws_.dof_b[m.row()] += m.value() * impulse;
        }
      }
    }
  }
  void updateVelocity() {
    for (Eigen::Index i = 0; i < r_.size() / 3; ++i) ws_.u.segment<3>(3 * i) = velocity(i);
  }

 private:
  const SparseMatrix& d_;
  const SparseMatrix& minv_;
  const Eigen::VectorXd& r_;
  Workspace& ws_;
};

}  // namespace rheofeed::ccp::detail
