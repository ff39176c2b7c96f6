// SPDX-License-Identifier: MIT
#include "bench/coulomb_residual.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rheofeed/ccp/cone.hpp"

namespace rheofeed::bench {

Eigen::VectorXd coulombErrors(const ccp::Problem& p, const Eigen::VectorXd& gamma,
                              const Eigen::VectorXd* shift) {
  const Eigen::VectorXd u = p.contactVelocity(gamma);
  Eigen::VectorXd errors(p.numContacts());
  for (Eigen::Index i = 0; i < p.numContacts(); ++i) {
    const double step = 3.0 / p.diagonalBlock(i).trace();
    Eigen::Vector3d v = u.segment<3>(3 * i);
    v[0] += shift ? (*shift)[i] : p.mu[i] * std::hypot(v[1], v[2]);
    const Eigen::Vector3d g = gamma.segment<3>(3 * i);
    errors[i] = ((g - ccp::projectOntoCone(g - step * v, p.mu[i])) / step).squaredNorm();
  }
  return errors;
}

double coulombResidual(const ccp::Problem& p, const Eigen::VectorXd& gamma,
                       const Eigen::VectorXd* shift) {
  const double error = coulombErrors(p, gamma, shift).sum();
  const double scale = std::max(p.r.norm(), (p.contactVelocity(gamma) - p.r).norm());
  if (error == 0.0) return 0.0;
  return scale > 0.0 ? std::sqrt(error) / scale : std::numeric_limits<double>::infinity();
}

}  // namespace rheofeed::bench
