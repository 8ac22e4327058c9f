// SPDX-License-Identifier: BSD-3-Clause
// The radar's terms on an IMU state (docs/design/solvers.md, "The sliding window").
// The state is the IMU's pose (R, p) in a gravity-aligned world G, its
// velocity v there and its biases; the radar sits at T_imu_radar = (R_e, t_e)
// on the IMU, and the scan matcher's world M is G turned by the tilt A (roll
// then pitch; M and G share the origin and the heading). A state stands at
// its scan's stamp as the IMU's samples were read at the clock offset t_0;
// at the offset t_d the scan was made d = t_d - t_0 later, and the state
// moves to it with the IMU's rate w - b_g and specific force f - b_a at the scan:
//
//   R_d = R Exp((w - b_g) d),  p_d = p + v d,  v_d = v + (R (f - b_a) + g) d
//   pose:     T_M_radar = A (R_d R_e, p_d + R_d t_e) against the match's Z:
//             r = W [ A (p_d + R_d t_e) - t_z ; Log(R_z^T A R_d R_e) ]
//             (the matcher's tangent: translation in the world, rotation on
//             the right, as its information; solvers/scan_matcher.hpp)
//   velocity: the radar's velocity in its own frame from the state,
//             r = W (L(v_r, b - b_0) - R_e^T (R_d^T v_d + (w - b_g) x t_e))
//             where the radar's elevations read b too high, b_0 of it was
//             removed from the scan, and L lowers the Doppler velocity's
//             elevation by the rest (its speed and azimuth kept)
//
// Blocks, pose: R (x y z w), p, [v; b_g; b_a], R_e (x y z w), t_e,
// [roll; pitch], t_d; velocity: R, [v; b_g; b_a], R_e, t_e, t_d, b.
#pragma once

#include <cmath>

#include <ceres/autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "radargauss/core/conventions.hpp"
#include "radargauss/lie/se3.hpp"
#include "radargauss/residuals/imu_residual.hpp"

namespace radargauss {

// A = Ry(pitch) Rx(roll): the scan matcher's world from the gravity-aligned one.
template <typename T>
SO3<T> TiltRotation(const T* roll_pitch) {
  using Vector3 = Eigen::Matrix<T, 3, 1>;
  return SO3<T>::Exp(Vector3(T(0), roll_pitch[1], T(0))) * SO3<T>::Exp(Vector3(roll_pitch[0], T(0), T(0)));
}

// The IMU's reading at the scan, and the clock offset the state's time assumed.
struct ImuAtScan {
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   // rad/s
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  // m/s^2
  double clock_offset = 0.0;                        // s: t_0
};

// The state moved by d = t_d - t_0 (the header's R_d, v_d; p_d = p + v d).
template <typename T>
void MovedState(const T* rotation, const T* motion, const T* clock_offset, const ImuAtScan& imu, SO3<T>& R_d,
                Eigen::Matrix<T, 3, 1>& p_shift, Eigen::Matrix<T, 3, 1>& v_d, Eigen::Matrix<T, 3, 1>& omega) {
  using Vector3 = Eigen::Matrix<T, 3, 1>;
  const Eigen::Map<const Vector3> v(motion + kMotionVelocity), bg(motion + kMotionGyroBias);
  const Eigen::Map<const Vector3> ba(motion + kMotionAccelBias);
  const T d = clock_offset[0] - T(imu.clock_offset);
  const SO3<T> R = SO3<T>::FromXyzw(rotation);
  omega = imu.gyro.cast<T>() - bg;
  R_d = R * SO3<T>::Exp(Vector3(omega * d));
  p_shift = v * d;
  const Vector3 gravity(T(0), T(0), T(-kGravity));
  v_d = v + (R * Vector3(imu.accel.cast<T>() - ba) + gravity) * d;
}

// L(v, delta): v with its elevation lowered by delta; v itself when it has
// no horizontal part. A scan whose elevations read delta too high fits a
// Doppler velocity raised by about delta (docs/design/simulator.md, "The faults of real radars").
template <typename T>
Eigen::Matrix<T, 3, 1> LowerElevation(const Eigen::Vector3d& v, const T& delta) {
  using std::cos;
  using std::sin;
  const double horizontal = std::hypot(v.x(), v.y());
  if (horizontal < 1e-9) return v.cast<T>();
  const double elevation = std::atan2(v.z(), horizontal), speed = v.norm();
  const T across = speed * cos(elevation - delta) / horizontal;
  return Eigen::Matrix<T, 3, 1>(across * v.x(), across * v.y(), speed * sin(elevation - delta));
}

class RadarPoseResidual {
 public:
  RadarPoseResidual(const SE3d& measured, const Eigen::Matrix<double, 6, 6>& sqrt_information, const ImuAtScan& imu)
      : measured_(measured), sqrt_information_(sqrt_information), imu_(imu) {}

  template <typename T>
  bool operator()(const T* rotation, const T* position, const T* motion, const T* extrinsic_rotation,
                  const T* extrinsic_translation, const T* tilt, const T* clock_offset, T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    SO3<T> R_d;
    Vector3 p_shift, v_d, omega;
    MovedState(rotation, motion, clock_offset, imu_, R_d, p_shift, v_d, omega);
    const SO3<T> A = TiltRotation(tilt);
    const SO3<T> Rz_inverse = measured_.rotation().Inverse().template cast<T>();
    const Vector3 radar_position = A * Vector3(Eigen::Map<const Vector3>(position) + p_shift +
                                               R_d * Eigen::Map<const Vector3>(extrinsic_translation));
    Eigen::Matrix<T, 6, 1> error;
    error.template segment<3>(kTranslationOffset) = radar_position - measured_.translation().template cast<T>();
    error.template segment<3>(kRotationOffset) = (Rz_inverse * A * R_d * SO3<T>::FromXyzw(extrinsic_rotation)).Log();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residual);
    r = sqrt_information_.cast<T>() * error;
    return true;
  }

  using AutoDiff = ceres::AutoDiffCostFunction<RadarPoseResidual, 6, 4, 3, 9, 4, 3, 2, 1>;
  // Defined in src/residuals/autodiff_costs.cpp (docs/design.md, "Build").
  static ceres::CostFunction* Create(const SE3d& measured, const Eigen::Matrix<double, 6, 6>& sqrt_information,
                                     const ImuAtScan& imu);

 private:
  const SE3d measured_;
  const Eigen::Matrix<double, 6, 6> sqrt_information_;
  const ImuAtScan imu_;
};

class RadarVelocityResidual {
 public:
  // elevation_bias_removed: b_0, the elevation bias taken off the scan before its Doppler fit (rad).
  RadarVelocityResidual(const Eigen::Vector3d& radar_velocity, const Eigen::Matrix3d& sqrt_information,
                        const ImuAtScan& imu, double elevation_bias_removed = 0.0)
      : radar_velocity_(radar_velocity),
        sqrt_information_(sqrt_information),
        imu_(imu),
        elevation_bias_removed_(elevation_bias_removed) {}

  template <typename T>
  bool operator()(const T* rotation, const T* motion, const T* extrinsic_rotation, const T* extrinsic_translation,
                  const T* clock_offset, const T* elevation_bias, T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    SO3<T> R_d;
    Vector3 p_shift, v_d, omega;
    MovedState(rotation, motion, clock_offset, imu_, R_d, p_shift, v_d, omega);
    const Vector3 predicted =
        SO3<T>::FromXyzw(extrinsic_rotation).Inverse() *
        Vector3(R_d.Inverse() * v_d + omega.cross(Eigen::Map<const Vector3>(extrinsic_translation)));
    const Vector3 measured = LowerElevation(radar_velocity_, T(elevation_bias[0] - elevation_bias_removed_));
    Eigen::Map<Vector3> r(residual);
    r = sqrt_information_.cast<T>() * (measured - predicted);
    return true;
  }

  using AutoDiff = ceres::AutoDiffCostFunction<RadarVelocityResidual, 3, 4, 9, 4, 3, 1, 1>;
  // Defined in src/residuals/autodiff_costs.cpp (docs/design.md, "Build").
  static ceres::CostFunction* Create(const Eigen::Vector3d& radar_velocity, const Eigen::Matrix3d& sqrt_information,
                                     const ImuAtScan& imu, double elevation_bias_removed = 0.0);

 private:
  const Eigen::Vector3d radar_velocity_;
  const Eigen::Matrix3d sqrt_information_;
  const ImuAtScan imu_;
  const double elevation_bias_removed_;
};

// A ground vehicle rolls along its own x axis: the velocity of an IMU
// aligned with it (and near its rear axle) has no lateral or vertical part
// in its own frame, r = [e_y e_z]^T R^T v / sigma. It tells a level drive
// with a radar whose elevations read high from a climb. Blocks: R, [v; b_g; b_a].
class VehicleMotionResidual {
 public:
  explicit VehicleMotionResidual(double sigma) : weight_(1.0 / sigma) {}

  template <typename T>
  bool operator()(const T* rotation, const T* motion, T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const Vector3 in_imu = SO3<T>::FromXyzw(rotation).Inverse() * Vector3(Eigen::Map<const Vector3>(motion));
    residual[0] = T(weight_) * in_imu.y();
    residual[1] = T(weight_) * in_imu.z();
    return true;
  }

  using AutoDiff = ceres::AutoDiffCostFunction<VehicleMotionResidual, 2, 4, 9>;
  // Defined in src/residuals/autodiff_costs.cpp (docs/design.md, "Build").
  static ceres::CostFunction* Create(double sigma);

 private:
  const double weight_;
};

// The analytic twins (docs/design/solvers.md, "The sliding window", gives each block).
class RadarPoseCostFunction final : public ceres::SizedCostFunction<6, 4, 3, 9, 4, 3, 2, 1> {
 public:
  RadarPoseCostFunction(const SE3d& measured, const Eigen::Matrix<double, 6, 6>& sqrt_information, const ImuAtScan& imu)
      : measured_(measured), sqrt_information_(sqrt_information), imu_(imu) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  const SE3d measured_;
  const Eigen::Matrix<double, 6, 6> sqrt_information_;
  const ImuAtScan imu_;
};

class RadarVelocityCostFunction final : public ceres::SizedCostFunction<3, 4, 9, 4, 3, 1, 1> {
 public:
  RadarVelocityCostFunction(const Eigen::Vector3d& radar_velocity, const Eigen::Matrix3d& sqrt_information,
                            const ImuAtScan& imu, double elevation_bias_removed = 0.0)
      : radar_velocity_(radar_velocity),
        sqrt_information_(sqrt_information),
        imu_(imu),
        elevation_bias_removed_(elevation_bias_removed) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  const Eigen::Vector3d radar_velocity_;
  const Eigen::Matrix3d sqrt_information_;
  const ImuAtScan imu_;
  const double elevation_bias_removed_;
};

class VehicleMotionCostFunction final : public ceres::SizedCostFunction<2, 4, 9> {
 public:
  explicit VehicleMotionCostFunction(double sigma) : weight_(1.0 / sigma) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  const double weight_;
};

}  // namespace radargauss
