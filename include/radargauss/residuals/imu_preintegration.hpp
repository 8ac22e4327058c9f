// SPDX-License-Identifier: BSD-3-Clause
// IMU preintegration on the manifold (Forster et al. 2017, "On-Manifold
// Preintegration for Real-Time Visual-Inertial Odometry"; docs/design/residuals.md,
// "IMU preintegration"): the rotation, velocity and position increments
// between two states from the samples in between, at a linearisation point
// of the biases, with their covariance and their Jacobians with respect to
// the biases for a first-order correction.
//
//   ImuPreintegration between(bias, noise);
//   for (each sample from t_i to t_j) between.Integrate(gyro, accel, dt);
//   const ImuDelta delta = between.Corrected(new_bias);  // or Reintegrate past MaxCorrection
#pragma once

#include <vector>

#include <Eigen/Core>

#include "radargauss/io/imu.hpp"
#include "radargauss/lie/so3.hpp"

namespace radargauss {

// The increments in the frame of the first state (body i):
// R_j = R_i dR, v_j = v_i + g dt + R_i dv, p_j = p_i + v_i dt + g dt^2 / 2 + R_i dp.
struct ImuDelta {
  SO3d rotation;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double duration = 0.0;  // s
};

class ImuPreintegration {
 public:
  using Matrix9 = Eigen::Matrix<double, 9, 9>;
  using Matrix93 = Eigen::Matrix<double, 9, 3>;

  // A bias change larger than this (per sensor, its norm) calls for Reintegrate.
  static constexpr double kMaxGyroCorrection = 0.01;  // rad/s
  static constexpr double kMaxAccelCorrection = 0.2;  // m/s^2

  ImuPreintegration(const ImuBias& linearisation, const ImuNoise& noise);

  // One sample held over `dt` seconds (the rates and specific force in the
  // IMU's frame). Throws std::invalid_argument for dt <= 0 or a non-finite value.
  void Integrate(const Eigen::Vector3d& gyro, const Eigen::Vector3d& accel, double dt);

  const ImuDelta& delta() const { return delta_; }
  const ImuBias& linearisation() const { return linearisation_; }
  // The covariance of [dphi; dv; dp] (the rotation's tangent on the right).
  const Matrix9& covariance() const { return covariance_; }
  // d[dphi; dv; dp] / d(gyro bias) and / d(accel bias).
  const Matrix93& gyro_jacobian() const { return gyro_jacobian_; }
  const Matrix93& accel_jacobian() const { return accel_jacobian_; }

  // The increments at `biases`, to first order about the linearisation.
  // Throws std::out_of_range when the change exceeds kMax*Correction:
  // the samples must be integrated again (Reintegrate).
  ImuDelta Corrected(const ImuBias& biases) const;
  bool WithinCorrection(const ImuBias& biases) const;

 private:
  ImuBias linearisation_;
  Eigen::Matrix3d gyro_covariance_, accel_covariance_;  // continuous: density^2
  ImuDelta delta_;
  Matrix9 covariance_ = Matrix9::Zero();
  Matrix93 gyro_jacobian_ = Matrix93::Zero();
  Matrix93 accel_jacobian_ = Matrix93::Zero();
};

// The samples (time order, each held until the next) integrated from `from`
// to `to`; the last one before `to` is held up to it. Throws DataError when
// no sample is at or before `from` or a sample is held longer than kMaxImuHold.
constexpr double kMaxImuHold = 0.05;  // s
ImuPreintegration Preintegrate(const std::vector<ImuSample>& samples, double from, double to, const ImuBias& bias,
                               const ImuNoise& noise);

}  // namespace radargauss
