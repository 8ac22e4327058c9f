// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/residuals/imu_residual.hpp"

#include <stdexcept>

#include <Eigen/Cholesky>

#include "radargauss/lie/manifold.hpp"

namespace radargauss {

Matrix15 ImuSqrtInformation(const ImuPreintegration& preintegration, const ImuNoise& noise) {
  const double dt = preintegration.delta().duration;
  Matrix15 covariance = Matrix15::Zero();
  covariance.topLeftCorner<9, 9>() = preintegration.covariance();
  const double gyro_walk = noise.gyro_bias_random_walk * noise.gyro_bias_random_walk * dt;
  const double accel_walk = noise.accel_bias_random_walk * noise.accel_bias_random_walk * dt;
  covariance.block<3, 3>(kImuGyroBias, kImuGyroBias) = gyro_walk * Eigen::Matrix3d::Identity();
  covariance.block<3, 3>(kImuAccelBias, kImuAccelBias) = accel_walk * Eigen::Matrix3d::Identity();
  // W = U of information = U^T U: the upper Cholesky factor of the inverse.
  const Eigen::LLT<Matrix15> covariance_factor(covariance);
  if (!(dt > 0.0) || covariance_factor.info() != Eigen::Success) {
    throw std::invalid_argument("ImuResidual: the increments' covariance is not positive definite (no samples?)");
  }
  const Matrix15 information = covariance_factor.solve(Matrix15::Identity());
  const Eigen::LLT<Matrix15> information_factor(0.5 * (information + information.transpose()));
  return information_factor.matrixU();
}

bool ImuCostFunction::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  using Eigen::Matrix3d;
  using Eigen::Vector3d;
  const ImuDelta& delta = preintegration_.delta();
  const SO3d Ri = SO3d::FromXyzw(parameters[0]), Rj = SO3d::FromXyzw(parameters[3]);
  const Eigen::Map<const Vector3d> pi(parameters[1]), pj(parameters[4]);
  const Eigen::Map<const Vector3d> vi(parameters[2] + kMotionVelocity), vj(parameters[5] + kMotionVelocity);
  const Eigen::Map<const Vector3d> bgi(parameters[2] + kMotionGyroBias), bgj(parameters[5] + kMotionGyroBias);
  const Eigen::Map<const Vector3d> bai(parameters[2] + kMotionAccelBias), baj(parameters[5] + kMotionAccelBias);
  const Vector3d dbg = bgi - preintegration_.linearisation().gyro;
  const Vector3d dba = bai - preintegration_.linearisation().accel;
  const auto& Jg = preintegration_.gyro_jacobian();
  const auto& Ja = preintegration_.accel_jacobian();
  const Vector3d rotation_correction = Jg.block<3, 3>(0, 0) * dbg;
  const SO3d dR = delta.rotation * SO3d::Exp(rotation_correction);
  const Vector3d dv = delta.velocity + Jg.block<3, 3>(3, 0) * dbg + Ja.block<3, 3>(3, 0) * dba;
  const Vector3d dp = delta.position + Jg.block<3, 3>(6, 0) * dbg + Ja.block<3, 3>(6, 0) * dba;
  const double dt = delta.duration;
  const Matrix3d Ri_T = Ri.Inverse().Matrix();
  const Vector3d velocity_change = Ri_T * (vj - vi - gravity_ * dt);
  const Vector3d position_change = Ri_T * (pj - pi - vi * dt - 0.5 * gravity_ * dt * dt);
  const SO3d E = dR.Inverse() * Ri.Inverse() * Rj;
  Eigen::Matrix<double, 15, 1> error;
  error.segment<3>(kImuRotation) = E.Log();
  error.segment<3>(kImuVelocity) = velocity_change - dv;
  error.segment<3>(kImuPosition) = position_change - dp;
  error.segment<3>(kImuGyroBias) = bgj - bgi;
  error.segment<3>(kImuAccelBias) = baj - bai;
  Eigen::Map<Eigen::Matrix<double, 15, 1>> r(residuals);
  r = sqrt_information_ * error;
  if (jacobians == nullptr) return true;

  // Tangent Jacobians of the error, block by block (the header's formulas).
  const Vector3d e_R = error.segment<3>(kImuRotation);
  const Matrix3d Jr_inverse = SO3d::RightJacobianInverse(e_R);
  const Matrix3d I = Matrix3d::Identity();
  Eigen::Matrix<double, 15, 3> rotation_i = Eigen::Matrix<double, 15, 3>::Zero();
  rotation_i.block<3, 3>(kImuRotation, 0) = -Jr_inverse * (Rj.Inverse() * Ri).Matrix();
  rotation_i.block<3, 3>(kImuVelocity, 0) = SO3d::Hat(velocity_change);
  rotation_i.block<3, 3>(kImuPosition, 0) = SO3d::Hat(position_change);
  Eigen::Matrix<double, 15, 3> position_i = Eigen::Matrix<double, 15, 3>::Zero();
  position_i.block<3, 3>(kImuPosition, 0) = -Ri_T;
  Eigen::Matrix<double, 15, 9> motion_i = Eigen::Matrix<double, 15, 9>::Zero();
  motion_i.block<3, 3>(kImuVelocity, kMotionVelocity) = -Ri_T;
  motion_i.block<3, 3>(kImuPosition, kMotionVelocity) = -Ri_T * dt;
  motion_i.block<3, 3>(kImuRotation, kMotionGyroBias) =
      -Jr_inverse * E.Inverse().Matrix() * SO3d::RightJacobian(rotation_correction) * Jg.block<3, 3>(0, 0);
  motion_i.block<3, 3>(kImuVelocity, kMotionGyroBias) = -Jg.block<3, 3>(3, 0);
  motion_i.block<3, 3>(kImuPosition, kMotionGyroBias) = -Jg.block<3, 3>(6, 0);
  motion_i.block<3, 3>(kImuGyroBias, kMotionGyroBias) = -I;
  motion_i.block<3, 3>(kImuVelocity, kMotionAccelBias) = -Ja.block<3, 3>(3, 0);
  motion_i.block<3, 3>(kImuPosition, kMotionAccelBias) = -Ja.block<3, 3>(6, 0);
  motion_i.block<3, 3>(kImuAccelBias, kMotionAccelBias) = -I;
  Eigen::Matrix<double, 15, 3> rotation_j = Eigen::Matrix<double, 15, 3>::Zero();
  rotation_j.block<3, 3>(kImuRotation, 0) = Jr_inverse;
  Eigen::Matrix<double, 15, 3> position_j = Eigen::Matrix<double, 15, 3>::Zero();
  position_j.block<3, 3>(kImuPosition, 0) = Ri_T;
  Eigen::Matrix<double, 15, 9> motion_j = Eigen::Matrix<double, 15, 9>::Zero();
  motion_j.block<3, 3>(kImuVelocity, kMotionVelocity) = Ri_T;
  motion_j.block<3, 3>(kImuGyroBias, kMotionGyroBias) = I;
  motion_j.block<3, 3>(kImuAccelBias, kMotionAccelBias) = I;

  // Rotations in the ambient quaternion: times 4 P^T (residuals/rotation_residual.hpp).
  const SO3Manifold so3;
  for (const int b : {0, 3}) {
    if (jacobians[b] == nullptr) continue;
    Eigen::Matrix<double, 4, 3, Eigen::RowMajor> P;
    so3.PlusJacobian(parameters[b], P.data());
    Eigen::Map<Eigen::Matrix<double, 15, 4, Eigen::RowMajor>> J(jacobians[b]);
    J = 4.0 * sqrt_information_ * (b == 0 ? rotation_i : rotation_j) * P.transpose();
  }
  for (const int b : {1, 4}) {
    if (jacobians[b] == nullptr) continue;
    Eigen::Map<Eigen::Matrix<double, 15, 3, Eigen::RowMajor>> J(jacobians[b]);
    J = sqrt_information_ * (b == 1 ? position_i : position_j);
  }
  for (const int b : {2, 5}) {
    if (jacobians[b] == nullptr) continue;
    Eigen::Map<Eigen::Matrix<double, 15, 9, Eigen::RowMajor>> J(jacobians[b]);
    J = sqrt_information_ * (b == 2 ? motion_i : motion_j);
  }
  return true;
}

}  // namespace radargauss
