// SPDX-License-Identifier: BSD-3-Clause
// IMU fixtures the tests share: gravity in the world frame (z up) and the
// samples of a turning, accelerating drive at 200 Hz (smooth, not exact),
// integrated from a bias linearisation.
#pragma once

#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "radargauss/residuals/imu_preintegration.hpp"
#include "radargauss/residuals/imu_residual.hpp"

namespace radargauss::testing {

inline const Eigen::Vector3d kGravityVector(0.0, 0.0, -kGravity);

// The first `count` samples (gyro, specific force) of the drive, 5 ms apart.
inline std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> TurningDriveSamples(int count) {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> samples;
  for (int k = 0; k < count; ++k) {
    const double t = k * 0.005;
    samples.push_back({Eigen::Vector3d(0.05 * std::sin(3 * t), -0.03, 0.4 + 0.2 * t),
                       Eigen::Vector3d(1.0 + std::cos(2 * t), 0.5 * t, 9.81 + 0.1 * std::sin(5 * t))});
  }
  return samples;
}

// Those samples preintegrated at `linearisation`.
inline ImuPreintegration IntegrateTurningDrive(const ImuBias& linearisation, int count) {
  ImuPreintegration between(linearisation, ImuNoise{});
  for (const auto& [gyro, force] : TurningDriveSamples(count)) between.Integrate(gyro, force, 0.005);
  return between;
}

}  // namespace radargauss::testing
