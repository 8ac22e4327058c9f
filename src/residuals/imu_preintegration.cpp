// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/residuals/imu_preintegration.hpp"

#include "radargauss/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <stdexcept>

namespace radargauss {

ImuPreintegration::ImuPreintegration(const ImuBias& linearisation, const ImuNoise& noise)
    : linearisation_(linearisation) {
  CheckOptions(ImuNoiseOptionTable(), noise);
  if (!linearisation.gyro.allFinite() || !linearisation.accel.allFinite()) {
    throw std::invalid_argument("ImuPreintegration: biases are not finite");
  }
  gyro_covariance_ = noise.gyro_noise_density * noise.gyro_noise_density * Eigen::Matrix3d::Identity();
  accel_covariance_ = noise.accel_noise_density * noise.accel_noise_density * Eigen::Matrix3d::Identity();
}

// Forster et al. 2017, eqs. 24-26 and appendix A-B: the position and velocity
// first (they use the rotation at the sample's start), then the rotation;
// the noise of a sample held over dt has covariance density^2 / dt.
void ImuPreintegration::Integrate(const Eigen::Vector3d& gyro, const Eigen::Vector3d& accel, double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt) || !gyro.allFinite() || !accel.allFinite()) {
    throw std::invalid_argument("ImuPreintegration: a sample needs finite rates and a positive dt");
  }
  const Eigen::Vector3d omega = gyro - linearisation_.gyro;
  const Eigen::Vector3d force = accel - linearisation_.accel;
  const Eigen::Matrix3d R = delta_.rotation.Matrix();
  const Eigen::Matrix3d force_hat = SO3d::Hat(force);
  const SO3d step = SO3d::Exp(omega * dt);
  const Eigen::Matrix3d right_jacobian = SO3d::RightJacobian(omega * dt);

  // The covariance: eta_{k+1} = A eta_k + B_g n_g + B_a n_a.
  Matrix9 A = Matrix9::Identity();
  A.block<3, 3>(0, 0) = step.Inverse().Matrix();
  A.block<3, 3>(3, 0) = -R * force_hat * dt;
  A.block<3, 3>(6, 0) = -0.5 * R * force_hat * dt * dt;
  A.block<3, 3>(6, 3) = Eigen::Matrix3d::Identity() * dt;
  Matrix93 B_g = Matrix93::Zero(), B_a = Matrix93::Zero();
  B_g.block<3, 3>(0, 0) = right_jacobian * dt;
  B_a.block<3, 3>(3, 0) = R * dt;
  B_a.block<3, 3>(6, 0) = 0.5 * R * dt * dt;
  covariance_ = A * covariance_ * A.transpose() + B_g * (gyro_covariance_ / dt) * B_g.transpose() +
                B_a * (accel_covariance_ / dt) * B_a.transpose();

  // The bias Jacobians, at the old rotation's Jacobian.
  const Eigen::Matrix3d dR_dbg = gyro_jacobian_.block<3, 3>(0, 0);
  gyro_jacobian_.block<3, 3>(6, 0) += gyro_jacobian_.block<3, 3>(3, 0) * dt - 0.5 * R * force_hat * dR_dbg * dt * dt;
  accel_jacobian_.block<3, 3>(6, 0) += accel_jacobian_.block<3, 3>(3, 0) * dt - 0.5 * R * dt * dt;
  gyro_jacobian_.block<3, 3>(3, 0) += -R * force_hat * dR_dbg * dt;
  accel_jacobian_.block<3, 3>(3, 0) += -R * dt;
  gyro_jacobian_.block<3, 3>(0, 0) = step.Inverse().Matrix() * dR_dbg - right_jacobian * dt;

  // The increments.
  delta_.position += delta_.velocity * dt + 0.5 * R * force * dt * dt;
  delta_.velocity += R * force * dt;
  delta_.rotation = delta_.rotation * step;
  delta_.duration += dt;
}

bool ImuPreintegration::WithinCorrection(const ImuBias& biases) const {
  return (biases.gyro - linearisation_.gyro).norm() <= kMaxGyroCorrection &&
         (biases.accel - linearisation_.accel).norm() <= kMaxAccelCorrection;
}

ImuDelta ImuPreintegration::Corrected(const ImuBias& biases) const {
  if (!WithinCorrection(biases)) {
    throw std::out_of_range("ImuPreintegration: the bias moved past the first-order correction; integrate again");
  }
  const Eigen::Vector3d dbg = biases.gyro - linearisation_.gyro;
  const Eigen::Vector3d dba = biases.accel - linearisation_.accel;
  ImuDelta corrected = delta_;
  corrected.rotation = delta_.rotation * SO3d::Exp(gyro_jacobian_.block<3, 3>(0, 0) * dbg);
  corrected.velocity += gyro_jacobian_.block<3, 3>(3, 0) * dbg + accel_jacobian_.block<3, 3>(3, 0) * dba;
  corrected.position += gyro_jacobian_.block<3, 3>(6, 0) * dbg + accel_jacobian_.block<3, 3>(6, 0) * dba;
  return corrected;
}

ImuPreintegration Preintegrate(const std::vector<ImuSample>& samples, double from, double to, const ImuBias& bias,
                               const ImuNoise& noise) {
  const auto after_from = std::upper_bound(samples.begin(), samples.end(), from,
                                           [](double t, const ImuSample& sample) { return t < sample.stamp; });
  if (!(to > from) || after_from == samples.begin()) {
    throw DataError("the IMU does not cover " + std::to_string(from) + " .. " + std::to_string(to) + " s");
  }
  ImuPreintegration between(bias, noise);
  for (auto sample = after_from - 1; sample != samples.end() && sample->stamp < to; ++sample) {
    const double start = std::max(from, sample->stamp);
    const double end = (sample + 1 == samples.end()) ? to : std::min(to, (sample + 1)->stamp);
    if (end - sample->stamp > kMaxImuHold) {
      throw DataError("the IMU has no sample from " + std::to_string(sample->stamp) + " to " + std::to_string(end) +
                      " s");
    }
    if (end > start) between.Integrate(sample->angular_velocity, sample->specific_force, end - start);
  }
  return between;
}

}  // namespace radargauss
