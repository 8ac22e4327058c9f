// SPDX-License-Identifier: BSD-3-Clause
#include "rig_reference_motion.hpp"

#include <cmath>

namespace radargauss::rig_calibration {

// The gyro's rates in the reference radar's frame on the body's clock, each
// at its interval's middle (a sample holds the mean rate to the next), less
// the window's gyro bias at the nearest state; none where the window never
// started or dropped the IMU.
std::vector<GyroSample> GyroRatesOf(const InertialMotion& inertial, std::vector<ImuSample> imu) {
  std::vector<std::pair<double, Eigen::Vector3d>> biases;
  for (const std::optional<InertialState>& state : inertial.states()) {
    if (state) biases.emplace_back(state->stamp, state->bias.gyro);
  }
  if (inertial.imu_fault() || biases.empty()) return {};
  ScreenImuSamples(imu, inertial.options().window.noise);
  const SO3d reference_from_imu = inertial.window().radar_from_imu().rotation();
  const double offset = inertial.window().clock_offset();  // the IMU's stamps minus the body's clock
  std::vector<GyroSample> rates;
  std::size_t b = 0;
  for (std::size_t i = 0; i + 1 < imu.size(); ++i) {
    const double t = 0.5 * (imu[i].stamp + imu[i + 1].stamp) - offset;
    while (b + 1 < biases.size() && std::abs(biases[b + 1].first - t) <= std::abs(biases[b].first - t)) ++b;
    rates.push_back({t, reference_from_imu * (imu[i].angular_velocity - biases[b].second)});
  }
  return rates;
}

}  // namespace radargauss::rig_calibration
