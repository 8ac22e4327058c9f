// SPDX-License-Identifier: BSD-3-Clause
// Analytic derivatives of quaternion rotations with respect to the four
// ambient coordinates x y z w (conventions.hpp), for the polynomial forms
// that Eigen evaluates (so they equal the Jet derivatives exactly):
//   R p   = p + 2 w (v x p) + 2 v x (v x p)
//   R^T a = a - 2 w (v x a) + 2 v x (v x a)
#pragma once

#include <Eigen/Core>

#include "radargauss/lie/so3.hpp"

namespace radargauss {

// d(R p)/d[x y z w], 3 x 4.
inline Eigen::Matrix<double, 3, 4> RotatePointJacobian(const double* xyzw, const Eigen::Vector3d& p) {
  const Eigen::Map<const Eigen::Vector3d> v(xyzw);
  const double w = xyzw[3];
  Eigen::Matrix<double, 3, 4> J;
  J.leftCols<3>() = -2.0 * w * SO3d::Hat(p) +
                    2.0 * (v * p.transpose() + v.dot(p) * Eigen::Matrix3d::Identity() - 2.0 * p * v.transpose());
  J.col(3) = 2.0 * v.cross(p);
  return J;
}

// lambda^T d(R^T a)/d[x y z w], 1 x 4, without forming the 3 x 4 Jacobian
// d(R^T a)/dv = 2 w [a]x + 2 (v a^T + (v . a) I - 2 a v^T),
// d(R^T a)/dw = -2 v x a, and lambda^T [a]x = (lambda x a)^T.
inline Eigen::Matrix<double, 1, 4> InverseRotatePointJacobianLeft(const Eigen::RowVector3d& lambda, const double* xyzw,
                                                                  const Eigen::Vector3d& a) {
  const Eigen::Map<const Eigen::Vector3d> v(xyzw);
  const double w = xyzw[3];
  const Eigen::Vector3d l = lambda.transpose();
  Eigen::Matrix<double, 1, 4> J;
  J.leftCols<3>() = (2.0 * w * l.cross(a) + 2.0 * (l.dot(v) * a + v.dot(a) * l - 2.0 * l.dot(a) * v)).transpose();
  J(3) = -2.0 * l.dot(v.cross(a));
  return J;
}

}  // namespace radargauss
