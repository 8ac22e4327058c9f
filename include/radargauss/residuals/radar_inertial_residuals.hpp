// SPDX-License-Identifier: BSD-3-Clause
// The radar's terms on an IMU state (docs/design.md, "The sliding window").
// The state is the IMU's pose (R, p) in a gravity-aligned world G, its
// velocity v there and its biases; the radar sits at T_imu_radar = (R_e, t_e)
// on the IMU, and the scan matcher's world M is G turned by the tilt A (roll
// then pitch; M and G share the origin and the heading):
//
//   pose:     T_M_radar = A (R R_e, p + R t_e) against the match's Z:
//             r = W [ A (p + R t_e) - t_z ; Log(R_z^T A R R_e) ]
//             (the matcher's tangent: translation in the world, rotation on
//             the right, as its information; solvers/scan_matcher.hpp)
//   velocity: the radar's velocity in its own frame from the state,
//             r = W (v_d - R_e^T (R^T v + (w - b_g) x t_e))
//
// with w the gyro rate at the scan. Blocks, pose: R (x y z w), p, R_e (x y z w),
// t_e, [roll; pitch]; velocity: R, [v; b_g; b_a], R_e, t_e.
#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>

#include "radargauss/conventions.hpp"
#include "radargauss/lie/se3.hpp"
#include "radargauss/residuals/imu_residual.hpp"

namespace radargauss {

// A = Ry(pitch) Rx(roll): the scan matcher's world from the gravity-aligned one.
template <typename T>
SO3<T> TiltRotation(const T* roll_pitch) {
  using Vector3 = Eigen::Matrix<T, 3, 1>;
  return SO3<T>::Exp(Vector3(T(0), roll_pitch[1], T(0))) * SO3<T>::Exp(Vector3(roll_pitch[0], T(0), T(0)));
}

class RadarPoseResidual {
 public:
  RadarPoseResidual(const SE3d& measured, const Eigen::Matrix<double, 6, 6>& sqrt_information)
      : measured_(measured), sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* rotation, const T* position, const T* extrinsic_rotation, const T* extrinsic_translation,
                  const T* tilt, T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const SO3<T> A = TiltRotation(tilt);
    const SO3<T> R = SO3<T>::FromXyzw(rotation);
    const SO3<T> Rz_inverse = measured_.rotation().Inverse().template cast<T>();
    const Vector3 radar_position =
        A * Vector3(Eigen::Map<const Vector3>(position) + R * Eigen::Map<const Vector3>(extrinsic_translation));
    Eigen::Matrix<T, 6, 1> error;
    error.template segment<3>(kTranslationOffset) = radar_position - measured_.translation().template cast<T>();
    error.template segment<3>(kRotationOffset) = (Rz_inverse * A * R * SO3<T>::FromXyzw(extrinsic_rotation)).Log();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residual);
    r = sqrt_information_.cast<T>() * error;
    return true;
  }

  using AutoDiff = ceres::AutoDiffCostFunction<RadarPoseResidual, 6, 4, 3, 4, 3, 2>;
  // Defined in residuals/autodiff_costs.cpp (docs/design.md, "Build").
  static ceres::CostFunction* Create(const SE3d& measured, const Eigen::Matrix<double, 6, 6>& sqrt_information);

 private:
  const SE3d measured_;
  const Eigen::Matrix<double, 6, 6> sqrt_information_;
};

class RadarVelocityResidual {
 public:
  RadarVelocityResidual(const Eigen::Vector3d& radar_velocity, const Eigen::Vector3d& gyro_rate,
                        const Eigen::Matrix3d& sqrt_information)
      : radar_velocity_(radar_velocity), gyro_rate_(gyro_rate), sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* rotation, const T* motion, const T* extrinsic_rotation, const T* extrinsic_translation,
                  T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Vector3> v(motion + kMotionVelocity), bg(motion + kMotionGyroBias);
    const Vector3 omega = gyro_rate_.cast<T>() - bg;
    const Vector3 imu_velocity = SO3<T>::FromXyzw(rotation).Inverse() * v;
    const Vector3 predicted = SO3<T>::FromXyzw(extrinsic_rotation).Inverse() *
                              Vector3(imu_velocity + omega.cross(Eigen::Map<const Vector3>(extrinsic_translation)));
    Eigen::Map<Vector3> r(residual);
    r = sqrt_information_.cast<T>() * (radar_velocity_.cast<T>() - predicted);
    return true;
  }

  using AutoDiff = ceres::AutoDiffCostFunction<RadarVelocityResidual, 3, 4, 9, 4, 3>;
  // Defined in residuals/autodiff_costs.cpp (docs/design.md, "Build").
  static ceres::CostFunction* Create(const Eigen::Vector3d& radar_velocity, const Eigen::Vector3d& gyro_rate,
                                     const Eigen::Matrix3d& sqrt_information);

 private:
  const Eigen::Vector3d radar_velocity_;
  const Eigen::Vector3d gyro_rate_;
  const Eigen::Matrix3d sqrt_information_;
};

}  // namespace radargauss
