// SPDX-License-Identifier: MIT
#include "rheofeed/ccp/problem.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <utility>

namespace rheofeed::ccp {

namespace {

// Largest coupled block of minv whose positive definiteness validate() checks exactly, with a
// fixed-capacity (heap-free) Cholesky factorisation. Rigid bodies give 6 x 6 blocks.
constexpr Eigen::Index kMaxCheckedMassBlock = 12;

using MassBlock = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxCheckedMassBlock,
                                kMaxCheckedMassBlock>;

std::string format(const char* fmt, ...) {
  char buffer[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buffer, sizeof buffer, fmt, args);
  va_end(args);
  return std::string(buffer);
}

std::string checkFinite(const Eigen::VectorXd& v, const char* name) {
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) return format("%s[%ld] = %g is not finite", name, long(i), v[i]);
  }
  return {};
}

std::string checkFinite(const SparseMatrix& m, const char* name) {
  for (Eigen::Index col = 0; col < m.outerSize(); ++col) {
    for (SparseMatrix::InnerIterator it(m, col); it; ++it) {
      if (!std::isfinite(it.value())) {
        return format("%s(%ld, %ld) = %g is not finite", name, long(it.row()), long(it.col()),
                      it.value());
      }
    }
  }
  return {};
}

// Checks positive diagonal and positive definiteness of minv's diagonal blocks.
std::string checkInverseMass(const SparseMatrix& minv) {
  const Eigen::Index ndof = minv.cols();
  for (Eigen::Index k = 0; k < ndof; ++k) {
    const double diag = minv.coeff(k, k);
    if (!(diag > 0.0)) {
      return format("minv(%ld, %ld) = %g: the inverse mass must have a positive diagonal (dof %ld)",
                    long(k), long(k), diag, long(k));
    }
  }
  // Coupled blocks: a block [start, end] closes at column j when no column in it reaches a row
  // beyond j.
  Eigen::Index start = 0;
  Eigen::Index end = 0;
  for (Eigen::Index col = 0; col < ndof; ++col) {
    end = std::max(end, col);
    for (SparseMatrix::InnerIterator it(minv, col); it; ++it) end = std::max(end, it.row());
    if (col != end) continue;
    const Eigen::Index size = end - start + 1;
    if (size > 1 && size <= kMaxCheckedMassBlock) {
      MassBlock block(size, size);
      block.setZero();
      for (Eigen::Index c = start; c <= end; ++c) {
        for (SparseMatrix::InnerIterator it(minv, c); it; ++it) {
          if (it.row() >= start) block(it.row() - start, c - start) = it.value();
        }
      }
      const MassBlock symmetric = 0.5 * (block + block.transpose());
      Eigen::LLT<MassBlock> llt(symmetric);
      if (llt.info() != Eigen::Success) {
        return format(
            "minv diagonal block of dofs %ld..%ld is not positive definite (not an inverse mass)",
            long(start), long(end));
      }
    }
    start = col + 1;
  }
  return {};
}

}  // namespace

const char* toString(DelassusForm form) {
  switch (form) {
    case DelassusForm::Dense:
      return "Dense";
    case DelassusForm::MatrixFree:
      return "MatrixFree";
  }
  return "Unknown";
}

Problem Problem::makeDense(Eigen::MatrixXd delassus, Eigen::VectorXd r, Eigen::VectorXd mu) {
  Problem problem;
  problem.form = DelassusForm::Dense;
  problem.delassus = std::move(delassus);
  problem.r = std::move(r);
  problem.mu = std::move(mu);
  return problem;
}

Problem Problem::makeMatrixFree(SparseMatrix d, SparseMatrix minv, Eigen::VectorXd r,
                                Eigen::VectorXd mu) {
  Problem problem;
  problem.form = DelassusForm::MatrixFree;
  problem.d = std::move(d);
  problem.minv = std::move(minv);
  problem.d.makeCompressed();
  problem.minv.makeCompressed();
  problem.r = std::move(r);
  problem.mu = std::move(mu);
  return problem;
}

Eigen::Matrix3d Problem::diagonalBlock(Eigen::Index contact) const {
  if (form == DelassusForm::Dense) return delassus.block<3, 3>(3 * contact, 3 * contact);
  // N_ii(a, b) = d_a^T minv d_b over the sparse columns d_a, d_b of contact i.
  Eigen::Matrix3d block = Eigen::Matrix3d::Zero();
  for (int b = 0; b < 3; ++b) {
    for (SparseMatrix::InnerIterator db(d, 3 * contact + b); db; ++db) {
      for (int a = 0; a < 3; ++a) {
        double sum = 0.0;
        for (SparseMatrix::InnerIterator da(d, 3 * contact + a); da; ++da) {
          sum += da.value() * minv.coeff(da.row(), db.row());
        }
        block(a, b) += sum * db.value();
      }
    }
  }
  return block;
}

Eigen::VectorXd Problem::contactVelocity(const Eigen::VectorXd& gamma) const {
  if (form == DelassusForm::Dense) return delassus * gamma + r;
  const Eigen::VectorXd generalised = minv * (d * gamma);
  return d.transpose() * generalised + r;
}

Eigen::MatrixXd Problem::denseDelassus() const {
  if (form == DelassusForm::Dense) return delassus;
  const SparseMatrix minv_d = minv * d;
  return Eigen::MatrixXd(d.transpose() * minv_d);
}

std::string Problem::validate() const {
  const Eigen::Index nc = mu.size();
  const Eigen::Index n = 3 * nc;
  if (r.size() != n) {
    return format("r has %ld entries, expected 3 * %ld contacts = %ld (size of mu: %ld)",
                  long(r.size()), long(nc), long(n), long(nc));
  }
  if (form == DelassusForm::Dense) {
    if (delassus.rows() != n || delassus.cols() != n) {
      return format("delassus is %ld x %ld, expected %ld x %ld (3 * %ld contacts)",
                    long(delassus.rows()), long(delassus.cols()), long(n), long(n), long(nc));
    }
  } else {
    if (d.cols() != n) {
      return format("d has %ld columns, expected 3 * %ld contacts = %ld", long(d.cols()), long(nc),
                    long(n));
    }
    if (minv.rows() != d.rows() || minv.cols() != d.rows()) {
      return format("minv is %ld x %ld, expected ndof x ndof = %ld x %ld (rows of d)",
                    long(minv.rows()), long(minv.cols()), long(d.rows()), long(d.rows()));
    }
  }
  for (Eigen::Index i = 0; i < nc; ++i) {
    if (!std::isfinite(mu[i])) return format("mu[%ld] = %g is not finite", long(i), mu[i]);
    if (mu[i] < 0.0) {
      return format("mu[%ld] = %g is negative (contact %ld)", long(i), mu[i], long(i));
    }
  }
  if (std::string message = checkFinite(r, "r"); !message.empty()) return message;
  if (form == DelassusForm::Dense) {
    for (Eigen::Index col = 0; col < n; ++col) {
      for (Eigen::Index row = 0; row < n; ++row) {
        const double value = delassus(row, col);
        if (!std::isfinite(value)) {
          return format("delassus(%ld, %ld) = %g is not finite", long(row), long(col), value);
        }
      }
    }
  } else {
    if (std::string message = checkFinite(d, "d"); !message.empty()) return message;
    if (std::string message = checkFinite(minv, "minv"); !message.empty()) return message;
    if (std::string message = checkInverseMass(minv); !message.empty()) return message;
  }
  for (Eigen::Index i = 0; i < nc; ++i) {
    const Eigen::Matrix3d block = diagonalBlock(i);
    const Eigen::Matrix3d symmetric = 0.5 * (block + block.transpose());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(symmetric, Eigen::EigenvaluesOnly);
    const double smallest = eigen.eigenvalues()[0];
    if (!(smallest > 0.0)) {
      return format(
          "diagonal block N_ii of contact %ld (rows %ld..%ld) is not positive definite: smallest "
          "eigenvalue of its symmetric part is %g",
          long(i), long(3 * i), long(3 * i + 2), smallest);
    }
  }
  return {};
}

double normalStabilisation(double phi, double h, double max_recovery_speed) {
  return std::max(phi / h, -max_recovery_speed);
}

std::string buildContactOffset(const SparseMatrix& d, const Eigen::VectorXd& v_free,
                               const Eigen::VectorXd& normal_term,
                               const Eigen::VectorXd& tangential_term, Eigen::VectorXd& r) {
  const Eigen::Index nc = normal_term.size();
  if (d.cols() != 3 * nc) {
    return format("d has %ld columns, expected 3 * %ld contacts (size of normal_term) = %ld",
                  long(d.cols()), long(nc), long(3 * nc));
  }
  if (tangential_term.size() != 2 * nc) {
    return format("tangential_term has %ld entries, expected 2 * %ld contacts = %ld",
                  long(tangential_term.size()), long(nc), long(2 * nc));
  }
  if (v_free.size() != d.rows()) {
    return format("v_free has %ld entries, expected ndof = %ld (rows of d)", long(v_free.size()),
                  long(d.rows()));
  }
  r.resize(3 * nc);
  r.noalias() = d.transpose() * v_free;
  for (Eigen::Index i = 0; i < nc; ++i) {
    r[3 * i] += normal_term[i];
    r[3 * i + 1] += tangential_term[2 * i];
    r[3 * i + 2] += tangential_term[2 * i + 1];
  }
  return {};
}

}  // namespace rheofeed::ccp
