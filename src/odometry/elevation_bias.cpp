// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/elevation_bias.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

#include "radargauss/core/stats.hpp"

namespace radargauss {

const OptionTable<ElevationBiasOptions>& ElevationBiasOptionTable() {
  using O = ElevationBiasOptions;
  static const OptionTable<O> table = {
      RADARGAUSS_OPTION(O, "estimate_elevation_bias", estimate)
          .Sensor()
          .Help("estimate the elevation bias (beyond the sequence's) from the Doppler velocity: needs the mounting, or "
                "with --imu the vehicle's motion term"),
      RADARGAUSS_OPTION(O, "elevation_bias_window", window).In(1, 1e6).Help("scans the bias's median is over"),
      RADARGAUSS_OPTION(O, "elevation_bias_min_speed", min_speed)
          .Above(0.0)
          .Unit("m/s")
          .Help("slower scans leave the bias"),
  };
  return table;
}

void ValidateOptions(const ElevationBiasOptions& o) { CheckOptions(ElevationBiasOptionTable(), o); }

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
  if (!options_.estimate || held_ || velocity.norm() < options_.min_speed) return;
  const Eigen::Vector3d forward = vehicle_from_radar_ * velocity;
  window_.push_back(std::atan2(forward.z(), forward.x()) + bias_);
  if (window_.size() > options_.window) window_.pop_front();
  bias_ = Median(std::vector<double>(window_.begin(), window_.end()));
}

void ElevationBias::Hold(double bias) {
  if (!std::isfinite(bias)) throw std::invalid_argument("ElevationBias::Hold: the bias is not finite");
  bias_ = bias;
  held_ = true;
}

}  // namespace radargauss
