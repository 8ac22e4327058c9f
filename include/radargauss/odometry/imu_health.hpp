// SPDX-License-Identifier: BSD-3-Clause
// The IMU checked against the radar (docs/design/odometry.md, "The IMU's
// health"): its accelerometer against gravity before the run, its gyro
// against the radar's matched rotations during it, and its clock against
// the radar's by cross-correlating their turn rates. The first fault found
// is kept with its cause; radar-inertial odometry then drops the IMU.
//
//   ImuHealth health(imu, radar_from_imu.rotation(), clock_offset);
//   for each scan: health.AddScan(stamp, matched_pose);
//   if (health.fault()) ...
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "radargauss/io/imu.hpp"
#include "radargauss/lie/se3.hpp"
#include "radargauss/odometry/motion_model.hpp"

namespace radargauss {

struct ImuFault {
  double stamp = 0.0;  // s, the radar's clock: when it was found
  std::string cause;   // one line
};

class ImuHealth {
 public:
  // The thresholds (docs/design/odometry.md, "The IMU's health").
  static constexpr double kGravityTolerance = 3.0;  // m/s^2: |mean specific force| - g
  static constexpr double kMaxUpAngleDeg = 60.0;    // gravity's reaction from the radar's up
  static constexpr double kSpan = 1.0;              // s: rotations compared over this
  static constexpr double kMinTurnDeg = 6.0;        // a span turning less is not compared
  static constexpr double kMaxAxisAngleDeg = 12.0;  // median angle between the two rotations' axes
  static constexpr double kMaxRateRatio = 1.4;      // median ratio of their angles, either way
  static constexpr int kMinTurns = 5;               // spans compared before judging
  static constexpr double kLagSearch = 1.5;         // s: the clock offsets the cross-correlation tries
  static constexpr double kMinHistory = 10.0;       // s of scans before the clocks are compared
  static constexpr double kClockTolerance = 0.15;   // s: a lag this far from the offset given is a fault
  static constexpr double kMaxProbation = 60.0;     // s of scans: then the IMU is taken as it is

  // `imu`: its samples on the scans' clock less `clock_offset` (the IMU's
  // stamps minus the radar's); radar_from_imu: R_radar_imu. Checks the
  // accelerometer against gravity over the first second.
  ImuHealth(const std::vector<ImuSample>& imu, const SO3d& radar_from_imu, double clock_offset);

  // A scan's matched T_world_radar.
  void AddScan(double stamp, const SE3d& matched);
  const std::optional<ImuFault>& fault() const { return fault_; }
  // No fault, and either every check has run (verified()) or kMaxProbation
  // has passed without the turns they need.
  bool confirmed() const { return confirmed_at_.has_value(); }
  bool verified() const { return verified_; }
  std::optional<double> confirmed_at() const { return confirmed_at_; }

 private:
  void CheckRotations(double stamp, const SE3d& matched);
  void CheckClock(double stamp);

  struct Scan {
    double stamp;
    SO3d rotation;
  };
  std::vector<double> stamps_, rate_integral_;  // the IMU's stamps and the integral of |w| up to each
  GyroRates rates_;                             // the raw rates in the radar's frame on its clock (no bias removed)
  double clock_offset_ = 0.0;
  std::deque<Scan> recent_;    // the scans of the last span
  std::vector<Scan> history_;  // every scan until the clocks were compared
  double last_compared_ = -1e300;
  std::vector<double> axis_angles_, rate_ratios_;
  bool clock_checked_ = false;
  std::optional<double> first_scan_, confirmed_at_;
  bool verified_ = false;
  std::optional<ImuFault> fault_;
};

}  // namespace radargauss
