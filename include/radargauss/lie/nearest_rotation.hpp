// SPDX-License-Identifier: BSD-3-Clause
// The rotation nearest a 3x3 matrix in the Frobenius norm: U diag(1, 1,
// det(U V^T)) V^T from the SVD M = U S V^T (the chordal projection on SO(3)).
#pragma once

#include <Eigen/Core>
#include <Eigen/SVD>

namespace radargauss {

inline Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& M) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

}  // namespace radargauss
