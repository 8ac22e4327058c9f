// SPDX-License-Identifier: BSD-3-Clause
// Radar-inertial odometry (docs/design/odometry.md, "Radar-inertial odometry"): the
// radar odometry of odometry/radar_odometry.hpp with an inertial window as
// its motion model. The prediction turns by the gyro's rates less the
// window's gyro bias; each scan's match (its pose and eq. 2's information)
// and Doppler velocity enter a sliding window of IMU states
// (solvers/inertial_window.hpp), and the window's pose of the radar is what
// the map and the prediction keep. The window starts at the first scan with
// a Doppler velocity that the IMU covers, from gravity.
//
//   RadarOdometry odometry(options, std::make_unique<InertialMotion>(inertial, radar_from_imu, imu));
//   for (const RadarScan& scan : sequence.scans) odometry.Register(scan);
#pragma once

#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/io/imu.hpp"
#include "radargauss/odometry/imu_health.hpp"
#include "radargauss/odometry/motion_model.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/core/options.hpp"
#include "radargauss/solvers/inertial_window.hpp"

namespace radargauss {

struct RadarInertialOptions {
  InertialWindowOptions window;
  // The match's covariance in the window (docs/design/odometry.md, "The
  // match in the window"): "information", the inverse of its Gauss-Newton
  // matrix N_geo H times match_information_scale; or "residuals", its own
  // (MatchCovariance) times match_covariance_inflation.
  std::string match_covariance = "information";
  // The map's error, shared by consecutive matches (the map was built at
  // the poses the window kept), which one scan's residuals cannot see.
  double match_covariance_inflation = 100.0;
  double match_information_scale = 0.003;
  double velocity_floor = 0.05;  // m/s: added in quadrature to the Doppler velocity's std
  // The motion model with an IMU (MakeMotionModel): "window", or "gyro" (the
  // gyro's rates for the prediction only).
  std::string fusion = "window";
  // Check the IMU against the radar (ImuHealth) and drop it on a fault.
  bool health_check = true;
};

// Its options (options.hpp): its own, then the window's.
const OptionTable<RadarInertialOptions>& RadarInertialOptionTable();

// The inertial window as the odometry's motion model: the prediction turns
// by the gyro's rates less the window's gyro bias, each scan's match and
// Doppler velocity enter the window, and the window's pose of the radar is
// the pose the scan keeps.
class InertialMotion : public MotionModel {
 public:
  // `imu`: the IMU's samples (time order) on the scans' clock, in its frame;
  // radar_from_imu = T_radar_imu. Samples beyond the IMU's ranges and
  // isolated spikes are dropped (ScreenImuSamples, counted in screening()).
  // Throws DataError for no samples, a value past the physical limits
  // (ImuSampleFault), or none within the ranges; the odometry that takes it
  // throws DataError for samples out of order, and its Register when the
  // IMU does not cover the time since the last scan.
  InertialMotion(const RadarInertialOptions& options, const SE3d& radar_from_imu, std::vector<ImuSample> imu);

  std::string name() const override { return "window"; }
  // Makes the window: with the odometry's estimate_elevation_bias it
  // estimates the bias, and the odometry removes its estimate from each scan.
  void Bind(bool estimate_elevation_bias) override;
  bool UsesMatchCovariance() const override { return options_.match_covariance == "residuals" && !imu_fault(); }
  void Advance(double stamp) override;
  std::optional<double> ElevationBias() const override;
  std::optional<SO3d> Rotation(double from, double to) const override {
    return imu_fault() ? std::nullopt : rates_.Rotation(from, to);
  }
  SE3d Fuse(const ScanEstimate& estimate) override;

  // The window's newest state after each scan; empty before the window started.
  const std::vector<std::optional<InertialState>>& states() const { return states_; }
  // Each solve's summary, one per scan since the window started.
  const std::vector<WindowSolveSummary>& solves() const { return solves_; }
  const InertialWindow& window() const { return *window_; }
  const RadarInertialOptions& options() const { return options_; }
  // The samples dropped before the window saw them.
  ImuScreening screening() const override { return screening_; }
  // On probation until the IMU's health is confirmed (ImuHealth).
  bool OnProbation() const override;
  bool Check(double stamp, const SE3d& radar_alone, bool matched) override;
  const ImuHealth& health() const { return *health_; }
  // The fault for which the IMU was dropped (the scans from then on are the
  // radar's alone); none while it holds.
  const std::optional<ImuFault>& imu_fault() const { return health_->fault(); }

 private:
  RadarInertialOptions options_;
  SE3d radar_from_imu_;
  std::vector<ImuSample> imu_;
  ImuScreening screening_;
  std::unique_ptr<InertialWindow> window_;  // made by Bind
  bool started_ = false;
  double elevation_bias_removed_ = 0.0;                         // rad: what the odometry removes from the scan now
  GyroRates rates_;                                             // less the gyro bias at the time they were handed on
  std::size_t fed_ = 0;                                         // IMU samples handed to rates_
  double last_fed_ = -std::numeric_limits<double>::infinity();  // their last stamp, on the radar's clock
  std::vector<std::optional<InertialState>> states_;
  std::vector<WindowSolveSummary> solves_;
  std::optional<ImuHealth> health_;
};

// The motion model named by options.fusion ("window": InertialMotion;
// "gyro": GyroModel) over `imu`; ConstantVelocityModel without an IMU.
std::unique_ptr<MotionModel> MakeMotionModel(const RadarInertialOptions& options, const SE3d& radar_from_imu,
                                             std::vector<ImuSample> imu);
// The odometry's inertial window; null when its motion model is another.
const InertialMotion* InertialMotionOf(const RadarOdometry& odometry);

}  // namespace radargauss
