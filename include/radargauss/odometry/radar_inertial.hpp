// SPDX-License-Identifier: BSD-3-Clause
// Radar-inertial odometry (docs/design/odometry.md, "Radar-inertial odometry"): the
// radar odometry of odometry/radar_odometry.hpp with an IMU. The prediction
// turns by the gyro's rates less the window's gyro bias; each scan's match
// (its pose and eq. 2's information) and Doppler velocity enter a sliding
// window of IMU states (solvers/inertial_window.hpp), and the window's pose
// of the radar is what the map and the motion model keep. The window starts
// at the first scan with a Doppler velocity that the IMU covers, from gravity.
//
//   RadarInertialOdometry odometry(options, inertial, radar_from_imu, imu);
//   for (const RadarScan& scan : sequence.scans) odometry.Register(scan);
#pragma once

#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "radargauss/io/imu.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/core/options.hpp"
#include "radargauss/solvers/inertial_window.hpp"

namespace radargauss {

struct RadarInertialOptions {
  InertialWindowOptions window;
  // The match's points are not independent (the map was built from the
  // same poses): its information N_geo * H counts for this fraction.
  double match_information_scale = 0.003;
  double velocity_floor = 0.05;  // m/s: added in quadrature to the Doppler velocity's std
};

// Its options (options.hpp): its own, then the window's.
const OptionTable<RadarInertialOptions>& RadarInertialOptionTable();

// The window beside a RadarOdometry: Attach sets its PoseFusion; around
// each Register, BeforeScan feeds the gyro's rates (less the window's bias)
// to the prediction and AfterScan records the window's state. RadarSlam and
// RadarInertialOdometry hold one.
class InertialFusion {
 public:
  // `imu`: the IMU's samples (time order) on the scans' clock, in its frame;
  // radar_from_imu = T_radar_imu. Samples beyond the IMU's ranges and
  // isolated spikes are dropped (ScreenImuSamples, counted in screening()).
  // Throws DataError for no samples, samples out of order, a value past the
  // physical limits (ImuSampleFault), or none within the ranges.
  InertialFusion(const RadarInertialOptions& options, const SE3d& radar_from_imu, std::vector<ImuSample> imu);
  InertialFusion(const InertialFusion&) = delete;  // the odometry's hook holds `this`
  InertialFusion& operator=(const InertialFusion&) = delete;

  // With the odometry's estimate_elevation_bias the window estimates the
  // bias, and the odometry removes the window's estimate from each scan.
  void Attach(RadarOdometry& odometry);
  void BeforeScan(RadarOdometry& odometry, double stamp);
  void AfterScan();

  // The window's newest state after each scan; empty before the window started.
  const std::vector<std::optional<InertialState>>& states() const { return states_; }
  // Each solve's summary, one per scan since the window started.
  const std::vector<WindowSolveSummary>& solves() const { return solves_; }
  const InertialWindow& window() const { return *window_; }
  const RadarInertialOptions& options() const { return options_; }
  // The samples dropped before the window saw them.
  const ImuScreening& screening() const { return screening_; }

 private:
  SE3d Fuse(const ScanEstimate& estimate);

  RadarInertialOptions options_;
  SE3d radar_from_imu_;
  std::vector<ImuSample> imu_;
  ImuScreening screening_;
  std::unique_ptr<InertialWindow> window_;  // made again by Attach when the elevation bias is estimated
  bool started_ = false;
  double elevation_bias_removed_ = 0.0;                         // rad: what the odometry removes from the scan now
  std::size_t fed_ = 0;                                         // IMU samples handed to the odometry's prediction
  double last_fed_ = -std::numeric_limits<double>::infinity();  // their last stamp, on the radar's clock
  std::vector<std::optional<InertialState>> states_;
  std::vector<WindowSolveSummary> solves_;
};

class RadarInertialOdometry {
 public:
  // As InertialFusion's; Register throws DataError when the IMU does not
  // cover the time since the last scan.
  RadarInertialOdometry(const OdometryOptions& odometry, const RadarInertialOptions& options,
                        const SE3d& radar_from_imu, std::vector<ImuSample> imu);

  const OdometryStep& Register(const RadarScan& scan);

  const RadarOdometry& odometry() const { return odometry_; }
  const InertialFusion& fusion() const { return fusion_; }
  const std::vector<std::optional<InertialState>>& states() const { return fusion_.states(); }
  const InertialWindow& window() const { return fusion_.window(); }
  const RadarInertialOptions& options() const { return fusion_.options(); }
  const ImuScreening& screening() const { return fusion_.screening(); }
  const std::vector<WindowSolveSummary>& solves() const { return fusion_.solves(); }

 private:
  InertialFusion fusion_;
  RadarOdometry odometry_;
};

}  // namespace radargauss
