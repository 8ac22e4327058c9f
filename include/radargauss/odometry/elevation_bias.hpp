// SPDX-License-Identifier: BSD-3-Clause
// A radar's constant elevation bias estimated from the Doppler velocity and
// removed from every point (docs/design/simulator.md, "The faults of real radars"; a
// known bias is removed as the sequence is read, SequenceOptions): a
// bias b lifts every return by b, and the Doppler fit then lifts the ego
// velocity by b too, while a vehicle moves along its own x axis. So the
// corrected velocity's elevation in the vehicle frame is what is left of the
// bias; the estimate is the median of (that + the bias removed) over the
// last `window` scans at speed.
//
//   ElevationBias bias(options);
//   const RadarScan corrected = bias.Corrected(scan);
//   ... (the ego velocity of `corrected`)
//   bias.Observe(velocity);
#pragma once

#include <cstddef>
#include <deque>

#include <Eigen/Core>

#include "radargauss/lie/so3.hpp"
#include "radargauss/core/options.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

struct ElevationBiasOptions {
  bool estimate = false;     // follow the Doppler velocity's elevation
  std::size_t window = 100;  // scans the median is over
  double min_speed = 5.0;    // m/s: slower scans are left out
};

// Its options (options.hpp); ValidateOptions throws std::invalid_argument naming the bad one.
const OptionTable<ElevationBiasOptions>& ElevationBiasOptionTable();
void ValidateOptions(const ElevationBiasOptions& options);

class ElevationBias {
 public:
  // vehicle_from_radar: the mounting (R_vehicle_radar).
  ElevationBias(const ElevationBiasOptions& options, const SO3d& vehicle_from_radar);

  bool active() const { return options_.estimate || held_; }
  double bias_deg() const;  // the estimate (0 until a scan at speed)
  // The scan with every point's elevation lowered by the current bias
  // (range and azimuth kept).
  RadarScan Corrected(const RadarScan& scan) const;
  // A measured ego velocity (radar frame) of a corrected scan.
  void Observe(const Eigen::Vector3d& velocity);
  // Removes `bias` (rad), estimated elsewhere, from now on; Observe then leaves it.
  void Hold(double bias);

 private:
  ElevationBiasOptions options_;
  SO3d vehicle_from_radar_;
  double bias_ = 0.0;          // rad
  bool held_ = false;          // set by Hold
  std::deque<double> window_;  // raw elevations: residual + the bias then removed (rad)
};

}  // namespace radargauss
