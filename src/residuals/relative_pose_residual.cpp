// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/residuals/relative_pose_residual.hpp"

#include "radargauss/lie/manifold.hpp"

namespace radargauss {

bool RelativePoseCostFunction::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const SO3d Ri = SO3d::FromXyzw(parameters[0]);
  const SO3d Rj = SO3d::FromXyzw(parameters[2]);
  const Eigen::Map<const Eigen::Vector3d> ti(parameters[1]);
  const Eigen::Map<const Eigen::Vector3d> tj(parameters[3]);
  const SO3d& Rz_inverse = measured_inverse_.rotation();
  const Eigen::Vector3d d = Ri.Inverse() * (tj - ti);
  const Eigen::Vector3d e = (Rz_inverse * Ri.Inverse() * Rj).Log();
  Eigen::Matrix<double, 6, 1> error;
  error.segment<3>(kTranslationOffset) = Rz_inverse * d + measured_inverse_.translation();
  error.segment<3>(kRotationOffset) = e;
  Eigen::Map<Eigen::Matrix<double, 6, 1>> r(residuals);
  r = sqrt_information_ * error;
  if (jacobians == nullptr) return true;

  // Tangent Jacobians of the error: rotation i, translation i, rotation j, translation j.
  const Eigen::Matrix3d Rz_T = Rz_inverse.Matrix();
  const Eigen::Matrix3d Rzi_T = Rz_T * Ri.Inverse().Matrix();
  const Eigen::Matrix3d Jr_inverse = SO3d::RightJacobianInverse(e);
  Eigen::Matrix<double, 6, 3> tangent[4];
  for (auto& block : tangent) block.setZero();
  tangent[0].block<3, 3>(kTranslationOffset, 0) = Rz_T * SO3d::Hat(d);
  tangent[0].block<3, 3>(kRotationOffset, 0) = -Jr_inverse * (Rj.Inverse() * Ri).Matrix();
  tangent[1].block<3, 3>(kTranslationOffset, 0) = -Rzi_T;
  tangent[2].block<3, 3>(kRotationOffset, 0) = Jr_inverse;
  tangent[3].block<3, 3>(kTranslationOffset, 0) = Rzi_T;
  const SO3Manifold so3;
  for (int b = 0; b < 4; ++b) {
    if (jacobians[b] == nullptr) continue;
    if (b == 1 || b == 3) {
      Eigen::Map<Eigen::Matrix<double, 6, 3, Eigen::RowMajor>> J(jacobians[b]);
      J = sqrt_information_ * tangent[b];
      continue;
    }
    Eigen::Matrix<double, 4, 3, Eigen::RowMajor> P;
    so3.PlusJacobian(parameters[b], P.data());
    Eigen::Map<Eigen::Matrix<double, 6, 4, Eigen::RowMajor>> J(jacobians[b]);
    J = 4.0 * sqrt_information_ * tangent[b] * P.transpose();
  }
  return true;
}

}  // namespace radargauss
