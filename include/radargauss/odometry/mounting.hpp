// SPDX-License-Identifier: BSD-3-Clause
// The radar's mounting pitch and yaw from the Doppler velocity's direction
// (docs/design/odometry.md, "Mounting"): driving straight, the vehicle moves along its
// own forward axis, so the measured velocity's direction in the radar frame
// is that axis. Roll about it is not observable this way. The levelled frame
// is the vehicle's at the first scan: T_level_radar = R_vehicle_radar T_world_radar.
//
//   const std::optional<Mounting> mounting = EstimateMounting(odometry.steps());
//   if (mounting) levelled = Levelled(odometry.trajectory(), *mounting);
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "radargauss/lie/so3.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/core/trajectory.hpp"

namespace radargauss {

struct MountingOptions {
  double min_speed = 5.0;         // m/s: slower scans say little about the direction
  double max_yaw_rate_deg = 2.0;  // deg/s: turning adds the lever arm's lateral velocity
  std::size_t min_scans = 10;     // straight scans at speed needed for an estimate
};

// Its options (options.hpp).
const OptionTable<MountingOptions>& MountingOptionTable();
// CheckOptions with that table: throws std::invalid_argument naming the bad option.
void ValidateOptions(const MountingOptions& options);

// R_vehicle_radar = Rz(yaw) Ry(pitch) (roll unobserved, 0), the convention
// of the simulator's mounting_* (z up: a positive pitch looks down).
struct Mounting {
  double pitch_deg = 0.0;                               // the radar's x axis below the direction of travel
  double yaw_deg = 0.0;                                 // the radar's x axis left of the direction of travel
  double pitch_spread_deg = 0.0, yaw_spread_deg = 0.0;  // 1.4826 x median absolute deviation
  std::size_t pitch_scans = 0, yaw_scans = 0;           // scans the medians are over
  SO3d vehicle_from_radar() const;                      // R_vehicle_radar: the radar's axes in the levelled frame
};

// Medians over the scans whose velocity was measured, at least min_speed;
// the yaw's over those whose yaw rate (from consecutive poses) stays below
// max_yaw_rate_deg as well. nullopt when fewer than min_scans are straight.
std::optional<Mounting> EstimateMounting(const std::vector<OdometryStep>& steps, const MountingOptions& options = {});

// The trajectory in the levelled frame.
Trajectory Levelled(const Trajectory& trajectory, const Mounting& mounting);

}  // namespace radargauss
