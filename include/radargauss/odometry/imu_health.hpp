// SPDX-License-Identifier: BSD-3-Clause
// The IMU checked against the radar (docs/design/odometry.md, "The IMU's
// health"): its accelerometer's magnitude against gravity before the run,
// its gyro and accelerometer against the radar's motion in the turns, and
// its clock against the radar's by cross-correlating their turn rates. The first fault found
// is kept with its cause; radar-inertial odometry then drops the IMU.
//
//   ImuHealth health(imu, radar_from_imu.rotation(), clock_offset);
//   for each scan: health.AddScan(stamp, radar_pose, matched);
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
  static constexpr double kGravityTolerance = 3.0;     // m/s^2: |mean specific force| - g
  static constexpr double kMinTurnAcceleration = 1.0;  // m/s^2: a span's acceleration compared with the force
  static constexpr double kSpan = 1.0;                 // s: rotations compared over this
  static constexpr double kMinTurnDeg = 6.0;           // a span turning less is not compared
  static constexpr double kMaxDisagreement = 0.25;     // |w_gyro - w_radar| summed over the turns, per turned
  static constexpr int kMinTurns = 5;                  // spans compared before judging
  static constexpr double kLagSearch = 1.5;            // s: the clock offsets the cross-correlation tries
  static constexpr double kMinHistory = 20.0;          // s of scans before the clocks are compared
  static constexpr double kClockTolerance = 0.15;      // s: a lag this far from the offset given is a fault
  static constexpr double kMaxProbation = 60.0;        // s of scans: then the IMU is taken as it is

  // `imu`: its samples on the scans' clock less `clock_offset` (the IMU's
  // stamps minus the radar's); radar_from_imu: R_radar_imu. Checks the
  // accelerometer against gravity over the first second.
  ImuHealth(const std::vector<ImuSample>& imu, const SO3d& radar_from_imu, double clock_offset);

  // A scan's T_world_radar from the radar alone; `matched`: the pose is a
  // match's, not a prediction's (a span is compared only when every scan
  // in it matched).
  void AddScan(double stamp, const SE3d& pose, bool matched);
  const std::optional<ImuFault>& fault() const { return fault_; }
  // No fault, and either every check has run (verified()) or kMaxProbation
  // has passed without the turns they need.
  bool confirmed() const { return confirmed_at_.has_value(); }
  bool verified() const { return verified_; }
  std::optional<double> confirmed_at() const { return confirmed_at_; }

 private:
  void CheckTurns(double stamp, const SE3d& pose);
  std::optional<Eigen::Vector3d> MeanForce(double from, double to) const;
  void CheckClock(double stamp);
  // The turn rates' magnitudes correlated over the lags; none on an even drive.
  struct ClockCorrelation {
    double lag = 0.0, best = -2.0, at_given = -2.0;
    bool Off(double given) const;  // a clear peak more than kClockTolerance from `given`
    std::string Cause(double given) const;
  };
  std::optional<ClockCorrelation> CorrelateClocks() const;

  struct Scan {
    double stamp;
    SE3d pose;
  };
  std::vector<double> stamps_, rate_integral_;   // the IMU's stamps and the integral of |w| up to each
  std::vector<Eigen::Vector3d> force_integral_;  // ... and of the specific force in the radar's frame
  GyroRates rates_;                              // the raw rates in the radar's frame on its clock (no bias removed)
  double clock_offset_ = 0.0;
  std::deque<Scan> recent_;    // the scans of the last span
  std::vector<Scan> history_;  // every matched scan of the probation
  double last_compared_ = -1e300;
  int turns_ = 0;
  double disagreement_ = 0.0, turned_ = 0.0;  // sum |w_gyro - w_radar|, sum |w_radar| (rad)
  std::vector<double> force_cosines_;
  bool clock_checked_ = false;
  std::optional<double> probation_start_;  // the first scan's stamp
  std::optional<double> first_matched_;    // the first matched scan's: the specific force's mean from here
  std::optional<double> confirmed_at_;
  bool verified_ = false;
  std::optional<ImuFault> fault_;
};

}  // namespace radargauss
