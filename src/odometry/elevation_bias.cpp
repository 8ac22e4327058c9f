// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/elevation_bias.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

#include "radargauss/stats.hpp"

namespace radargauss {

void ValidateOptions(const ElevationBiasOptions& o) {
  if (o.window < 1) throw std::invalid_argument("elevation bias window must be >= 1 scan");
  if (!(o.min_speed > 0.0) || !std::isfinite(o.min_speed)) {
    throw std::invalid_argument("elevation bias minimum speed must be positive");
  }
}

ElevationBias::ElevationBias(const ElevationBiasOptions& options, const SO3d& vehicle_from_radar)
    : options_(options), vehicle_from_radar_(vehicle_from_radar) {
  ValidateOptions(options_);
}

double ElevationBias::bias_deg() const { return bias_ * 180.0 / M_PI; }

RadarScan ElevationBias::Corrected(const RadarScan& scan) const {
  RadarScan corrected = scan;
  LowerElevations(corrected, bias_);
  return corrected;
}

void ElevationBias::Observe(const Eigen::Vector3d& velocity) {
  if (!options_.estimate || velocity.norm() < options_.min_speed) return;
  const Eigen::Vector3d forward = vehicle_from_radar_ * velocity;
  window_.push_back(std::atan2(forward.z(), forward.x()) + bias_);
  if (window_.size() > options_.window) window_.pop_front();
  bias_ = Median(std::vector<double>(window_.begin(), window_.end()));
}

}  // namespace radargauss
