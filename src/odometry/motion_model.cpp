// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/motion_model.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>
#include <utility>

#include "radargauss/core/error.hpp"

namespace radargauss {

void GyroRates::Add(const std::vector<GyroSample>& samples) {
  for (const GyroSample& sample : samples) {
    if (!std::isfinite(sample.stamp) || !sample.rate.allFinite()) {
      throw DataError("gyro sample at " + std::to_string(sample.stamp) + " s is not finite");
    }
    if (!samples_.empty() && !(sample.stamp > samples_.back().stamp)) {
      throw DataError("gyro stamps must increase (" + std::to_string(sample.stamp) + " s after " +
                      std::to_string(samples_.back().stamp) + " s)");
    }
    samples_.push_back(sample);
  }
}

std::optional<SO3d> GyroRates::Rotation(double from, double to) const {
  auto it = std::upper_bound(samples_.begin(), samples_.end(), from,
                             [](double t, const GyroSample& s) { return t < s.stamp; });
  if (it == samples_.begin() || it == samples_.end() || samples_.back().stamp < to) return std::nullopt;
  --it;  // the sample in force at `from`
  SO3d increment;
  double t = from;
  for (; it != samples_.end() && t < to; ++it) {
    const double until = std::next(it) == samples_.end() ? to : std::min(to, std::next(it)->stamp);
    increment = increment * SO3d::Exp(it->rate * (until - t));
    t = until;
  }
  return increment;
}

GyroModel::GyroModel(std::vector<ImuSample> imu, const SE3d& radar_from_imu, const ImuNoise& noise) {
  screening_ = ScreenImuSamples(imu, noise);
  const SO3d rotation = radar_from_imu.rotation();
  std::vector<GyroSample> rates;
  rates.reserve(imu.size());
  for (const ImuSample& sample : imu) rates.push_back({sample.stamp, rotation * sample.angular_velocity});
  rates_.Add(rates);
}

}  // namespace radargauss
