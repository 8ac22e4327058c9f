// SPDX-License-Identifier: BSD-3-Clause
// The odometry's motion source (docs/design/odometry.md, "Motion models"):
// what turns the radar between scans and which pose a scan keeps. The
// odometry owns one, given at construction, and asks it in the same order
// for every scan: Advance, ElevationBias, Rotation, Fuse.
//
//   RadarOdometry odometry(options, std::make_unique<GyroModel>(imu, radar_from_imu, noise));
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/io/imu.hpp"
#include "radargauss/lie/se3.hpp"

namespace radargauss {

// Gyro rates in the radar frame (rad/s), stamped.
struct GyroSample {
  double stamp = 0.0;
  Eigen::Vector3d rate = Eigen::Vector3d::Zero();
};

// A scan's estimate before its pose is kept: what a model that fuses other
// sensors (odometry/radar_inertial.hpp) needs.
struct ScanEstimate {
  double stamp = 0.0;
  SE3d pose;             // T_world_radar: matched, or predicted
  bool matched = false;  // `information` and `matched_points` hold
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();  // eq. 2's, normalised
  std::size_t matched_points = 0;                                                 // N_geo
  // The match's own covariance (ScanMatchingResult::covariance); zero when unknown.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool velocity_measured = false;
  bool standstill = false;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s, radar frame
  Eigen::Matrix3d velocity_covariance = Eigen::Matrix3d::Zero();
};

// Gyro rates held piecewise constant from each sample to the next.
class GyroRates {
 public:
  // Appends samples; throws DataError for a stamp that is not finite or not
  // after the last one, or a rate that is not finite.
  void Add(const std::vector<GyroSample>& samples);
  // The rotation over [from, to], if the samples cover it.
  std::optional<SO3d> Rotation(double from, double to) const;

 private:
  std::vector<GyroSample> samples_;
};

class MotionModel {
 public:
  virtual ~MotionModel() = default;

  // Its name in the table of models ("constant_velocity", "gyro", "window").
  virtual std::string name() const = 0;
  // Called once by the odometry that takes the model: whether it estimates
  // an elevation bias (the inertial window then estimates it instead).
  virtual void Bind(bool /*estimate_elevation_bias*/) {}
  // Whether Fuse reads ScanEstimate::covariance (the odometry then asks the
  // matcher for it: ScanMatchingOptions::pose_covariance).
  virtual bool UsesMatchCovariance() const { return false; }
  // The scan at `stamp` arrives: the model brings its sources up to it.
  virtual void Advance(double /*stamp*/) {}
  // The elevation bias (rad) to remove from the scan; none: the odometry's own estimate.
  virtual std::optional<double> ElevationBias() const { return std::nullopt; }
  // The radar's rotation over [from, to]; none: the odometry turns at its last yaw rate.
  virtual std::optional<SO3d> Rotation(double /*from*/, double /*to*/) const { return std::nullopt; }
  // The pose the scan keeps (for the map, the prediction and the record).
  virtual SE3d Fuse(const ScanEstimate& estimate) { return estimate.pose; }
  // The IMU samples dropped before use (ScreenImuSamples); none without an IMU.
  virtual ImuScreening screening() const { return {}; }
  // While true, the odometry runs the radar alone beside the model and
  // hands it each scan's pose from there (Check): a reference the model's
  // sensor cannot bend, until the sensor has proved itself.
  virtual bool OnProbation() const { return false; }
  // The radar alone's pose of the scan at `stamp` (matched or predicted).
  // False: the model failed; the odometry goes on as the radar alone from
  // this scan, whose Fuse the model does not see.
  virtual bool Check(double /*stamp*/, const SE3d& /*radar_alone*/, bool /*matched*/) { return true; }
};

// The last velocity kept and the last yaw rate: the odometry's own prediction.
class ConstantVelocityModel : public MotionModel {
 public:
  std::string name() const override { return "constant_velocity"; }
};

// The gyro's rates for the rotation of the prediction; the scan's pose as matched.
class GyroModel : public MotionModel {
 public:
  // The IMU's samples (its frame, time order) turned into the radar frame by
  // T_radar_imu's rotation, after ScreenImuSamples with `noise`'s ranges.
  GyroModel(std::vector<ImuSample> imu, const SE3d& radar_from_imu, const ImuNoise& noise);

  std::string name() const override { return "gyro"; }
  std::optional<SO3d> Rotation(double from, double to) const override { return rates_.Rotation(from, to); }
  ImuScreening screening() const override { return screening_; }

 private:
  GyroRates rates_;
  ImuScreening screening_;
};

}  // namespace radargauss
