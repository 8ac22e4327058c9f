// SPDX-License-Identifier: BSD-3-Clause
// The preintegrated IMU term between two states (Forster et al. 2017, eq. 45;
// docs/design/residuals.md, "The IMU term"). A state is the IMU's pose in a
// gravity-aligned world (R, p), its velocity v there and its biases b_g, b_a;
// with the increments corrected to first order at b_i (ImuPreintegration):
//
//   r_R = Log(dR(b_i)^T R_i^T R_j)
//   r_v = R_i^T (v_j - v_i - g dt) - dv(b_i)
//   r_p = R_i^T (p_j - p_i - v_i dt - g dt^2 / 2) - dp(b_i)
//   r_b = b_j - b_i                          (the biases' random walk)
//
// weighted by a square root of the inverse of the increments' covariance and
// of the random walk's over dt. Blocks: R_i (x y z w), p_i, [v_i; b_g,i; b_a,i],
// then the same at j. The correction is linear however far b_i moves; the
// window integrates again when a bias leaves ImuPreintegration's bound.
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "radargauss/io/imu.hpp"
#include "radargauss/residuals/imu_preintegration.hpp"

namespace radargauss {

using Matrix15 = Eigen::Matrix<double, 15, 15>;

// The residual's offsets: rotation, velocity, position, gyro bias, accelerometer bias.
inline constexpr int kImuRotation = 0, kImuVelocity = 3, kImuPosition = 6, kImuGyroBias = 9, kImuAccelBias = 12;
// In a motion block [v; b_g; b_a].
inline constexpr int kMotionVelocity = 0, kMotionGyroBias = 3, kMotionAccelBias = 6;

// W with W^T W = diag(the increments' covariance, sigma_bg^2 dt I, sigma_ba^2 dt I)^-1.
// Throws std::invalid_argument when that covariance is not positive definite.
Matrix15 ImuSqrtInformation(const ImuPreintegration& preintegration, const ImuNoise& noise);

class ImuResidual {
 public:
  ImuResidual(const ImuPreintegration& preintegration, const ImuNoise& noise,
              const Eigen::Vector3d& gravity = Eigen::Vector3d(0.0, 0.0, -kGravity))
      : preintegration_(preintegration),
        gravity_(gravity),
        sqrt_information_(ImuSqrtInformation(preintegration, noise)) {}

  template <typename T>
  bool operator()(const T* rotation_i, const T* position_i, const T* motion_i, const T* rotation_j, const T* position_j,
                  const T* motion_j, T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const ImuDelta& delta = preintegration_.delta();
    const SO3<T> Ri_inverse = SO3<T>::FromXyzw(rotation_i).Inverse();
    const Eigen::Map<const Vector3> pi(position_i), pj(position_j);
    const Eigen::Map<const Vector3> vi(motion_i + kMotionVelocity), vj(motion_j + kMotionVelocity);
    const Eigen::Map<const Vector3> bgi(motion_i + kMotionGyroBias), bgj(motion_j + kMotionGyroBias);
    const Eigen::Map<const Vector3> bai(motion_i + kMotionAccelBias), baj(motion_j + kMotionAccelBias);
    const Vector3 dbg = bgi - preintegration_.linearisation().gyro.cast<T>();
    const Vector3 dba = bai - preintegration_.linearisation().accel.cast<T>();
    const auto& Jg = preintegration_.gyro_jacobian();
    const auto& Ja = preintegration_.accel_jacobian();
    const SO3<T> dR = delta.rotation.template cast<T>() * SO3<T>::Exp(Jg.block<3, 3>(0, 0).cast<T>() * dbg);
    const Vector3 dv =
        delta.velocity.cast<T>() + Jg.block<3, 3>(3, 0).cast<T>() * dbg + Ja.block<3, 3>(3, 0).cast<T>() * dba;
    const Vector3 dp =
        delta.position.cast<T>() + Jg.block<3, 3>(6, 0).cast<T>() * dbg + Ja.block<3, 3>(6, 0).cast<T>() * dba;
    const T dt(delta.duration);
    const Vector3 g = gravity_.cast<T>();
    Eigen::Matrix<T, 15, 1> error;
    error.template segment<3>(kImuRotation) = (dR.Inverse() * Ri_inverse * SO3<T>::FromXyzw(rotation_j)).Log();
    error.template segment<3>(kImuVelocity) = Ri_inverse * Vector3(vj - vi - g * dt) - dv;
    error.template segment<3>(kImuPosition) = Ri_inverse * Vector3(pj - pi - vi * dt - T(0.5) * g * dt * dt) - dp;
    error.template segment<3>(kImuGyroBias) = bgj - bgi;
    error.template segment<3>(kImuAccelBias) = baj - bai;
    Eigen::Map<Eigen::Matrix<T, 15, 1>> r(residual);
    r = sqrt_information_.cast<T>() * error;
    return true;
  }

  using AutoDiff = ceres::AutoDiffCostFunction<ImuResidual, 15, 4, 3, 9, 4, 3, 9>;
  // Defined in src/residuals/autodiff_costs.cpp (docs/design.md, "Build").
  static ceres::CostFunction* Create(const ImuPreintegration& preintegration, const ImuNoise& noise,
                                     const Eigen::Vector3d& gravity = Eigen::Vector3d(0.0, 0.0, -kGravity));

 private:
  const ImuPreintegration preintegration_;
  const Eigen::Vector3d gravity_;
  const Matrix15 sqrt_information_;
};

// The analytic twin (docs/design/residuals.md, "The IMU term", gives each block). With
// right perturbations R Exp(phi), additive p, v and b, and e_R the rotation
// error: de_R/dphi_j = Jr^-1(e_R), de_R/dphi_i = -Jr^-1(e_R) R_j^T R_i,
// de_R/db_g,i = -Jr^-1(e_R) Exp(e_R)^T Jr(J_R^g db_g) J_R^g; the velocity and
// position errors are linear in v, p and b, and turn with R_i^T.
class ImuCostFunction final : public ceres::SizedCostFunction<15, 4, 3, 9, 4, 3, 9> {
 public:
  ImuCostFunction(const ImuPreintegration& preintegration, const ImuNoise& noise,
                  const Eigen::Vector3d& gravity = Eigen::Vector3d(0.0, 0.0, -kGravity))
      : preintegration_(preintegration),
        gravity_(gravity),
        sqrt_information_(ImuSqrtInformation(preintegration, noise)) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  const ImuPreintegration preintegration_;
  const Eigen::Vector3d gravity_;
  const Matrix15 sqrt_information_;
};

}  // namespace radargauss
