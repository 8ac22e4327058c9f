// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/radar_inertial.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include <Eigen/Cholesky>

#include "radargauss/core/error.hpp"

namespace radargauss {

const OptionTable<RadarInertialOptions>& RadarInertialOptionTable() {
  using O = RadarInertialOptions;
  static const OptionTable<O> table = [] {
    OptionTable<O> t = {
        RADARGAUSS_OPTION(O, "imu_fusion", fusion)
            .Choices({"window", "gyro"})
            .Sensor()
            .Help("window: a sliding window of IMU states with the matches and Doppler velocities (biases, "
                  "gravity); gyro: the gyro's rates for the prediction only"),
        RADARGAUSS_OPTION(O, "imu_health_check", health_check)
            .Help("check the IMU against the radar (gravity, the gyro's axes and scale, the clocks) and drop it "
                  "on a fault"),
        RADARGAUSS_OPTION(O, "match_covariance", match_covariance)
            .Choices({"information", "residuals"})
            .Help("the match's covariance in the window: information, its Gauss-Newton matrix times "
                  "match_information_scale; residuals, its residuals' own spread times "
                  "match_covariance_inflation"),
        RADARGAUSS_OPTION(O, "match_covariance_inflation", match_covariance_inflation)
            .In(1.0, 1e6)
            .Help("how many times over the window counts a match's own covariance (the map's shared error)"),
        RADARGAUSS_OPTION(O, "match_information_scale", match_information_scale)
            .In(0.0, 1.0)
            .Help("with match_covariance information: the share of a match's N_geo H the window trusts"),
        RADARGAUSS_OPTION(O, "inertial_velocity_floor", velocity_floor)
            .In(0.0, 100.0)
            .Unit("m/s")
            .Help("std added in quadrature to the Doppler velocity's in the window"),
    };
    AppendNested(
        t, InertialWindowOptionTable(), +[](O & o) -> auto& { return o.window; }, "window");
    return t;
  }();
  return table;
}

InertialMotion::InertialMotion(const RadarInertialOptions& options, const SE3d& radar_from_imu,
                               std::vector<ImuSample> imu)
    : options_(options), radar_from_imu_(radar_from_imu), imu_(std::move(imu)) {
  CheckOptions(RadarInertialOptionTable(), options);
  if (imu_.empty()) throw DataError("the IMU has no sample");
  for (const ImuSample& sample : imu_) {
    const std::string fault = ImuSampleFault(sample);
    if (!fault.empty()) throw DataError("IMU sample at " + std::to_string(sample.stamp) + " s: " + fault);
  }
  screening_ = ScreenImuSamples(imu_, options.window.noise);
  if (imu_.empty()) throw DataError("no IMU sample within the IMU's range (--imu-gyro-range, --imu-accel-range)");
  health_.emplace(options.health_check ? imu_ : std::vector<ImuSample>{}, radar_from_imu.rotation(),
                  options.window.clock_offset);
}

// The window is made here, where the odometry's choice of the elevation bias is known.
void InertialMotion::Bind(bool estimate_elevation_bias) {
  if (window_) throw std::logic_error("InertialMotion::Bind: the model is bound to an odometry already");
  options_.window.estimate_elevation_bias = estimate_elevation_bias;
  window_ = std::make_unique<InertialWindow>(options_.window, radar_from_imu_);
  window_->AddImu(imu_);  // checks the order
}

std::optional<double> InertialMotion::ElevationBias() const {
  if (!options_.window.estimate_elevation_bias || imu_fault()) return std::nullopt;
  return elevation_bias_removed_;
}

// Hands the rates up to the first sample at or after `stamp` (the rotation
// needs one) to the prediction, less the window's gyro bias now, turned into
// the radar frame.
void InertialMotion::Advance(double stamp) {
  if (imu_fault()) return;
  const Eigen::Vector3d bias = started_ ? window_->newest().bias.gyro : Eigen::Vector3d::Zero();
  const SO3d radar_from_imu = window_->radar_from_imu().rotation();
  const double offset = window_->clock_offset();  // the IMU's stamps minus the radar's
  if (options_.window.estimate_elevation_bias) elevation_bias_removed_ = window_->elevation_bias();
  std::vector<GyroSample> samples;
  for (; fed_ < imu_.size() && (fed_ == 0 || imu_[fed_ - 1].stamp - offset < stamp); ++fed_) {
    const double on_radar_clock = imu_[fed_].stamp - offset;
    if (on_radar_clock <= last_fed_) continue;  // the offset moved back by more than a sample
    samples.push_back({on_radar_clock, radar_from_imu * (imu_[fed_].angular_velocity - bias)});
    last_fed_ = on_radar_clock;
  }
  rates_.Add(samples);
}

SE3d InertialMotion::Fuse(const ScanEstimate& e) {
  if (imu_fault()) {
    states_.push_back(std::nullopt);
    return e.pose;
  }
  if (!started_) {
    // The window starts at the first scan with a Doppler velocity that the IMU covers.
    if (!e.velocity_measured || imu_.empty() || imu_.front().stamp > e.stamp + options_.window.clock_offset) {
      states_.push_back(std::nullopt);
      return e.pose;
    }
    const InertialStart start =
        StartFromGravity(imu_, e.stamp, e.pose, e.velocity, radar_from_imu_, 0.2, options_.window.clock_offset);
    window_->set_tilt(start.tilt);
    window_->Start(start.state);
    started_ = true;
  } else {
    window_->AddState(e.stamp);
  }
  if (e.matched && options_.match_covariance == "residuals") {
    // A match of too few Gaussians to state its covariance is left out.
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> factor(e.covariance * options_.match_covariance_inflation);
    if (factor.info() == Eigen::Success && factor.vectorD().minCoeff() > 0.0) {
      window_->AddPose(e.pose, factor.solve(Eigen::Matrix<double, 6, 6>::Identity()));
    }
  } else if (e.matched && e.matched_points > 0) {
    window_->AddPose(e.pose, e.information * (double(e.matched_points) * options_.match_information_scale));
  }
  if (e.velocity_measured) {
    const Eigen::Matrix3d covariance =
        e.velocity_covariance + options_.velocity_floor * options_.velocity_floor * Eigen::Matrix3d::Identity();
    window_->AddVelocity(e.velocity, covariance, elevation_bias_removed_);
  }
  solves_.push_back(window_->Solve());
  states_.push_back(window_->newest());
  return window_->RadarPoseInMatcherWorld();
}

bool InertialMotion::OnProbation() const { return options_.health_check && !health_->fault() && !health_->confirmed(); }

bool InertialMotion::Check(double stamp, const SE3d& radar_alone, bool matched) {
  health_->AddScan(stamp, radar_alone, matched);
  if (!health_->fault()) return true;
  states_.push_back(std::nullopt);  // the scan is the radar's alone
  return false;
}

std::unique_ptr<MotionModel> MakeMotionModel(const RadarInertialOptions& options, const SE3d& radar_from_imu,
                                             std::vector<ImuSample> imu) {
  if (imu.empty()) return std::make_unique<ConstantVelocityModel>();
  if (options.fusion == "gyro")
    return std::make_unique<GyroModel>(std::move(imu), radar_from_imu, options.window.noise);
  if (options.fusion == "window") return std::make_unique<InertialMotion>(options, radar_from_imu, std::move(imu));
  throw std::invalid_argument("imu_fusion: no motion model '" + options.fusion + "' (window, gyro)");
}

const InertialMotion* InertialMotionOf(const RadarOdometry& odometry) {
  return dynamic_cast<const InertialMotion*>(&odometry.motion());
}

}  // namespace radargauss
