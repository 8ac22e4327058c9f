// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/radar_odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <Eigen/Eigenvalues>

#include "radargauss/core/conventions.hpp"
#include "radargauss/core/error.hpp"

namespace radargauss {

const OptionTable<OdometryOptions>& OdometryOptionTable() {
  using O = OdometryOptions;
  static const OptionTable<O> table = [] {
    OptionTable<O> t = {
        RADARGAUSS_OPTION(O, "mounting", mounting_deg)
            .In(-45.0, 45.0)
            .Unit("deg")
            .Sensor()
            .Help("the radar on the vehicle: roll pitch yaw (positive pitch looks down; odometry prints an estimate)"),
        RADARGAUSS_OPTION(O, "velocity_weight", velocity_weight)
            .AtLeast(0.0)
            .Help("weight of the Doppler velocity term (0: off)"),
        RADARGAUSS_OPTION(O, "velocity_floor", velocity_floor)
            .Above(0.0)
            .Unit("m")
            .Help("std of the velocity term's floor Q"),
        RADARGAUSS_OPTION(O, "velocity_vertical_floor", velocity_vertical_floor)
            .AtLeast(0.0)
            .Unit("m")
            .Help("its floor along the radar's z (0: velocity_floor); larger leaves the vertical to the map"),
        RADARGAUSS_OPTION(O, "rotation_weight", rotation_weight)
            .AtLeast(0.0)
            .Help("weight of the rotation term (0: off)"),
        RADARGAUSS_OPTION(O, "rotation_rate_std", rotation_rate_std_deg)
            .Above(0.0)
            .Unit("deg/s")
            .Help("rotation term: change of the rate between scans about x y z (roll pitch yaw)"),
        RADARGAUSS_OPTION(O, "gate_sigmas", gate_sigmas)
            .Above(0.0)
            .Help("Doppler gate around the predicted velocity (sigmas)"),
        RADARGAUSS_OPTION(O, "acceleration_std", acceleration_std)
            .AtLeast(0.0)
            .Unit("m/s^2")
            .Help("process noise of the velocity"),
        RADARGAUSS_OPTION(O, "min_gate", min_gate).Above(0.0).Unit("m/s").Help("smallest Doppler gate"),
        RADARGAUSS_OPTION(O, "min_static_points", min_static_points)
            .AtLeast(3)
            .Help("fewer Doppler inliers: the prediction stands in"),
        RADARGAUSS_OPTION(O, "keyframe_distance", keyframe_distance)
            .AtLeast(0.0)
            .Unit("m")
            .Help("a scan enters the map after this distance since the last keyframe ..."),
        RADARGAUSS_OPTION(O, "keyframe_angle", keyframe_angle_deg)
            .AtLeast(0.0)
            .Unit("deg")
            .Help("... or this rotation"),
        RADARGAUSS_OPTION(O, "background_map_update", background_map_update)
            .Help("a keyframe's map update behind the scan's step, on its own thread (the same results)"),
        RADARGAUSS_OPTION(O, "min_matched_points", min_matched_points)
            .AtLeast(3)
            .Help("fewer associated points: the prediction stands in"),
        RADARGAUSS_OPTION(O, "initial_pose", initial_pose).Help("T_world_radar of the first scan: x y z qx qy qz qw"),
    };
    AppendNested(
        t, EgoVelocityOptionTable(), +[](O & o) -> auto& { return o.ego_velocity; }, "ego_velocity");
    AppendNested(
        t, MatchOptionTable(), +[](O & o) -> auto& { return o.match; }, "match");
    AppendNested(
        t, LocalMapOptionTable(), +[](O & o) -> auto& { return o.map; }, "map");
    AppendNested(
        t, ElevationBiasOptionTable(), +[](O & o) -> auto& { return o.elevation_bias; }, "elevation_bias");
    AppendNested(
        t, RigOdometryOptionTable(), +[](O & o) -> auto& { return o.rig; }, "rig");
    return t;
  }();
  return table;
}

void ValidateOptions(const OdometryOptions& o) { CheckOptions(OdometryOptionTable(), o); }

MatcherFactory GaussianMatcherFactory() {
  return [](const LocalMap&, const MatchOptions& match) {
    return std::shared_ptr<const ScanMatcher>(MakeScanMatcher(match));
  };
}

RadarOdometry::RadarOdometry(const OdometryOptions& options, std::unique_ptr<MotionModel> motion,
                             MatcherFactory factory)
    : options_(options),
      vehicle_from_radar_(VehicleFromRadar(options.mounting_deg)),
      elevation_bias_(options.elevation_bias, vehicle_from_radar_),
      motion_(motion ? std::move(motion) : std::make_unique<ConstantVelocityModel>()),
      factory_(factory ? std::move(factory) : GaussianMatcherFactory()),
      map_(options.map) {
  ValidateOptions(options_);
  motion_->Bind(options_.elevation_bias.estimate);
  const std::size_t threads =
      std::min<std::size_t>(std::size_t(std::max(1, tbb::this_task_arena::max_concurrency())),
                            tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  if (options_.background_map_update && threads > 1) map_update_ = NewMapUpdateTask();
}

const ScanMatcher& RadarOdometry::MatcherForMap() {
  if (!matcher_ || matcher_version_ != map_.version()) {
    MatchOptions match = options_.match;  // the pose's covariance too when the model reads it
    match.matching.pose_covariance = match.matching.pose_covariance || motion_->UsesMatchCovariance();
    matcher_ = factory_(map_, match);
    if (!matcher_) throw std::invalid_argument("the matcher factory returned no matcher");
    matcher_version_ = map_.version();
    ++matchers_made_;
  }
  return *matcher_;
}

void RadarOdometry::LocalizeIn(std::shared_ptr<const MatchingMap> map, const SE3d& map_from_odometry) {
  if (!map) throw std::invalid_argument("LocalizeIn: no map");
  FinishMapUpdate();
  fixed_map_ = std::move(map);
  if (state_) {
    state_->pose = map_from_odometry * state_->pose;
    if (state_->before) state_->before->second = map_from_odometry * state_->before->second;
  }
  last_keyframe_ = map_from_odometry * last_keyframe_;
}

SO3d VehicleFromRadar(const Eigen::Vector3d& roll_pitch_yaw_deg) {
  const Eigen::Vector3d angles = roll_pitch_yaw_deg * (M_PI / 180.0);
  return SO3d::Exp(Eigen::Vector3d(0.0, 0.0, angles.z())) * SO3d::Exp(Eigen::Vector3d(0.0, angles.y(), 0.0)) *
         SO3d::Exp(Eigen::Vector3d(angles.x(), 0.0, 0.0));
}

RadarOdometry::Velocity RadarOdometry::MeasureVelocity(const RadarScan& scan,
                                                       const std::optional<Prediction>& prediction,
                                                       const std::optional<MeasuredVelocity>& measured) const {
  Velocity v;
  if (prediction) {
    v.value = prediction->velocity;
    v.covariance = prediction->velocity_covariance;
  }
  if (!scan.has_doppler) {
    for (std::size_t i = 0; i < scan.points.size(); ++i) v.static_points.push_back(i);
    if (measured) {
      v.measured = true;
      v.value = measured->value;
      v.covariance = measured->covariance;
      return v;
    }
    v.reason = "no Doppler field: velocity predicted, every point matched";
    return v;
  }
  std::optional<VelocityGate> gate;
  if (prediction && state_->measured) {
    const auto& [measured_stamp, measured_covariance] = *state_->measured;
    const double dt = scan.timestamp - measured_stamp;
    gate = VelocityGate{prediction->velocity, VelocityGateWidth(measured_covariance, dt, options_.gate_sigmas,
                                                                options_.acceleration_std, options_.min_gate)};
  }
  const EgoVelocityResult ego = EstimateEgoVelocity(scan, options_.ego_velocity, gate);
  for (std::size_t i = 0; i < ego.inlier.size(); ++i) {
    if (ego.inlier[i]) v.static_points.push_back(i);
  }
  if (!ego.success || (!ego.zero_velocity && v.static_points.size() < options_.min_static_points)) {
    v.reason = ego.success ? "too few static points (" + std::to_string(v.static_points.size()) +
                                 "): velocity and pose predicted"
                           : "ego velocity: " + ego.reason + ": velocity and pose predicted";
    v.static_points.clear();
    return v;
  }
  v.measured = true;
  v.standstill = ego.zero_velocity;
  v.value = ego.velocity;
  v.covariance = ego.covariance;
  return v;
}

// Kiss-icp's shape: each stage returns a value, the step is assembled at the end.
bool RadarOdometry::RunBeside(const RadarScan& scan, const std::optional<MeasuredVelocity>& measured) {
  if (!motion_->OnProbation() || fixed_map_) {
    radar_alone_.reset();
    return false;
  }
  if (!radar_alone_) radar_alone_ = std::make_unique<RadarOdometry>(options_, nullptr, factory_);
  const OdometryStep& alone = radar_alone_->Register(scan, measured);
  if (motion_->Check(alone.stamp, alone.pose, alone.matched)) return false;
  // The model failed: the radar alone's run goes on as this one, the model kept for its record.
  radar_alone_->FinishMapUpdate();
  FinishMapUpdate();
  std::unique_ptr<MotionModel> model = std::move(motion_);
  std::unique_ptr<RadarOdometry> radar_alone = std::move(radar_alone_);
  *this = std::move(*radar_alone);
  motion_ = std::move(model);
  return true;
}

const OdometryStep& RadarOdometry::Register(const RadarScan& input) { return Register(input, std::nullopt); }

const OdometryStep& RadarOdometry::Register(const RadarScan& input, const std::optional<MeasuredVelocity>& measured) {
  const auto start = std::chrono::steady_clock::now();
  if (measured && input.has_doppler)
    throw std::invalid_argument("a velocity measured apart is for scans without Doppler");
  if (RunBeside(input, measured)) return steps_.back();
  CheckStamp(input);
  motion_->Advance(input.timestamp);
  if (const std::optional<double> bias = motion_->ElevationBias()) elevation_bias_.Hold(*bias);
  const bool correct = elevation_bias_.active();
  const RadarScan corrected = correct ? elevation_bias_.Corrected(input) : RadarScan();
  const RadarScan& scan = correct ? corrected : input;
  std::optional<Prediction> prediction;
  if (state_) prediction = Predict(scan.timestamp);
  if (prediction && !prediction->gyro && measured && measured->rate && state_->rate)  // a gyro's rates come first
    PredictFromRates(*state_->rate, *measured->rate, *prediction);
  const Velocity velocity = MeasureVelocity(scan, prediction, measured);
  if (velocity.measured && !velocity.standstill) elevation_bias_.Observe(velocity.value);
  FinishMapUpdate();  // the map is read from here on
  PoseEstimate estimate = EstimatePose(scan, prediction, velocity);
  estimate.pose = motion_->Fuse(EstimateOf(scan, velocity, estimate));
  const bool keyframe = !fixed_map_ && IsKeyframe(estimate.pose, velocity);
  OdometryStep step = StepOf(scan, prediction, velocity, estimate, keyframe);
  const std::size_t index = steps_.size();
  if (keyframe) InsertKeyframe(scan, velocity.static_points, estimate.pose, index);
  last_static_points_ = velocity.static_points;
  step.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (!keyframe) {
    if (!state_) map_bytes_ = map_.MemoryBytes();
    step.active_gaussians = map_.gaussians();
    step.active_map_bytes = map_bytes_;
  }
  MotionState next;
  next.stamp = step.stamp;
  next.pose = step.pose;
  if (state_) next.before = std::make_pair(state_->stamp, state_->pose);
  next.velocity = step.velocity;
  next.velocity_covariance = step.velocity_covariance;
  next.measured = velocity.measured ? std::make_optional(std::make_pair(step.stamp, step.velocity_covariance))
                                    : (state_ ? state_->measured : std::nullopt);
  if (measured) next.rate = measured->rate;
  state_ = next;
  steps_.push_back(step);
  // Counted outside the step's time: the map changes on keyframes only.
  if (keyframe && !pending_step_) RecordMap(index, true);
  return steps_.back();
}

void RadarOdometry::CheckStamp(const RadarScan& scan) const {
  if (!std::isfinite(scan.timestamp)) throw DataError("scan stamp is not finite");
  if (state_ && !(scan.timestamp > state_->stamp)) {
    throw DataError("scan stamps must increase: " + std::to_string(scan.timestamp) + " s after " +
                    std::to_string(state_->stamp) + " s");
  }
  ValidateScan(scan, "scan at " + std::to_string(scan.timestamp) + " s");
}

RadarOdometry::PoseEstimate RadarOdometry::EstimatePose(const RadarScan& scan,
                                                        const std::optional<Prediction>& prediction,
                                                        const Velocity& velocity) {
  if (!prediction) return {options_.initial_pose, std::nullopt, false, ""};
  if (velocity.standstill) return {state_->pose, std::nullopt, false, ""};  // standing: the pose holds
  const SE3d predicted = PredictedPose(*prediction, velocity.value);
  if (velocity.static_points.size() < options_.min_static_points) return {predicted, std::nullopt, false, ""};
  return Match(scan, *prediction, velocity, predicted);
}

RadarOdometry::PoseEstimate RadarOdometry::Match(const RadarScan& scan, const Prediction& prediction,
                                                 const Velocity& velocity, const SE3d& predicted) {
  RadarScan matched;
  matched.timestamp = scan.timestamp;
  matched.has_doppler = scan.has_doppler;
  matched.has_rcs = scan.has_rcs;
  matched.points.reserve(velocity.static_points.size());
  for (const std::size_t i : velocity.static_points) matched.points.push_back(scan.points[i]);
  PoseEstimate estimate{predicted, std::nullopt, false, ""};
  const MatchingMap& target = fixed_map_ ? *fixed_map_ : map_.matching();
  estimate.match = MatcherForMap().Match(matched, target, predicted, PriorsOf(prediction, velocity));
  const ScanMatchingResult& result = *estimate.match;
  const bool usable = result.pose.translation().allFinite() && result.n_geo >= options_.min_matched_points;
  if (!usable) {
    estimate.reason =
        "matching: " + (result.reason.empty() ? std::string("too few points associated") : result.reason) +
        ": pose predicted";
    return estimate;
  }
  estimate.pose = result.pose;
  estimate.matched = true;
  if (!result.converged) estimate.reason = "matching: " + result.reason;
  return estimate;
}

bool RadarOdometry::IsKeyframe(const SE3d& pose, const Velocity& velocity) const {
  if (velocity.standstill || velocity.static_points.empty()) return false;
  if (!state_) return true;
  const SE3d moved = last_keyframe_.Inverse() * pose;
  return moved.translation().norm() >= options_.keyframe_distance ||
         moved.rotation().Log().norm() >= options_.keyframe_angle_deg * M_PI / 180.0;
}

ScanEstimate RadarOdometry::EstimateOf(const RadarScan& scan, const Velocity& velocity, const PoseEstimate& estimate) {
  ScanEstimate e;
  e.stamp = scan.timestamp;
  e.pose = estimate.pose;
  e.matched = estimate.matched;
  if (estimate.matched) {
    e.information = estimate.match->information;
    e.matched_points = estimate.match->n_geo;
    e.covariance = estimate.match->covariance;
  }
  e.velocity_measured = velocity.measured;
  e.standstill = velocity.standstill;
  e.velocity = velocity.value;
  e.velocity_covariance = velocity.covariance;
  return e;
}

OdometryStep RadarOdometry::StepOf(const RadarScan& scan, const std::optional<Prediction>& prediction,
                                   const Velocity& velocity, const PoseEstimate& estimate, bool keyframe) const {
  OdometryStep step;
  step.stamp = scan.timestamp;
  step.pose = estimate.pose;
  step.points = scan.points.size();
  step.static_points = velocity.static_points.size();
  step.velocity_measured = velocity.measured;
  step.standstill = velocity.standstill;
  step.gyro = prediction && prediction->gyro;
  step.velocity = velocity.value;
  step.velocity_covariance = velocity.covariance;
  step.matched = estimate.matched;
  if (estimate.match) {
    step.iterations = estimate.match->iterations;
    step.final_cost = estimate.match->final_cost;
    step.converged = estimate.matched && estimate.match->converged;
  }
  if (estimate.matched) {
    step.information = estimate.match->information;
    step.velocity_information = estimate.match->velocity_information;
    step.rotation_information = estimate.match->rotation_information;
  }
  step.reason = velocity.reason;
  if (!estimate.reason.empty()) step.reason += (step.reason.empty() ? "" : "; ") + estimate.reason;
  step.keyframe = keyframe;
  return step;
}

Trajectory RadarOdometry::trajectory() const {
  Trajectory trajectory;
  for (const OdometryStep& step : steps_) trajectory.Append(step.stamp, step.pose);
  return trajectory;
}

}  // namespace radargauss
