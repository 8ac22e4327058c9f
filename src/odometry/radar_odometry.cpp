// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/radar_odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "radargauss/conventions.hpp"
#include "radargauss/error.hpp"

namespace radargauss {

void ValidateOptions(const OdometryOptions& o) {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(what);
  };
  const auto finite_non_negative = [](double x) { return std::isfinite(x) && x >= 0.0; };
  require(finite_non_negative(o.gate_sigmas) && o.gate_sigmas > 0.0, "velocity gate sigmas must be > 0 and finite");
  require(finite_non_negative(o.acceleration_std), "acceleration std must be >= 0 and finite");
  require(finite_non_negative(o.min_gate) && o.min_gate > 0.0, "minimum velocity gate must be > 0 m/s and finite");
  require(o.min_static_points >= 3, "minimum static points must be >= 3");
  require(finite_non_negative(o.velocity_weight), "velocity weight must be >= 0 and finite");
  require(finite_non_negative(o.velocity_floor) && o.velocity_floor > 0.0, "velocity floor must be > 0 m and finite");
  require(finite_non_negative(o.rotation_weight), "rotation weight must be >= 0 and finite");
  require(o.rotation_rate_std_deg.allFinite() && (o.rotation_rate_std_deg.array() > 0.0).all(),
          "rotation rate stds must be > 0 deg/s and finite");
  require(finite_non_negative(o.keyframe_distance), "keyframe distance must be >= 0 m and finite");
  require(finite_non_negative(o.keyframe_angle_deg), "keyframe angle must be >= 0 deg and finite");
  require(o.min_matched_points >= 3, "minimum matched points must be >= 3");
  ValidateOptions(o.match.matching);
  ValidateOptions(o.map);
}

RadarOdometry::RadarOdometry(const OdometryOptions& options)
    : RadarOdometry(options, [](const LocalMap&, const MatchOptions& match) {
        return std::shared_ptr<const ScanMatcher>(MakeScanMatcher(match));
      }) {}

RadarOdometry::RadarOdometry(const OdometryOptions& options, MatcherFactory matcher)
    : options_(options), matcher_(std::move(matcher)), map_(options.map) {
  ValidateOptions(options_);
  if (!matcher_) throw std::invalid_argument("RadarOdometry needs a matcher factory");
}

void RadarOdometry::AddGyro(const std::vector<GyroSample>& samples) {
  for (const GyroSample& sample : samples) {
    if (!std::isfinite(sample.stamp) || !sample.rate.allFinite()) {
      throw DataError("gyro sample at " + std::to_string(sample.stamp) + " s is not finite");
    }
    if (!gyro_.empty() && !(sample.stamp > gyro_.back().stamp)) {
      throw DataError("gyro stamps must increase (" + std::to_string(sample.stamp) + " s after " +
                      std::to_string(gyro_.back().stamp) + " s)");
    }
    gyro_.push_back(sample);
  }
}

std::optional<SO3d> RadarOdometry::GyroIncrement(double from, double to) const {
  // Rates held piecewise constant from each sample to the next, over [from, to].
  auto it = std::upper_bound(gyro_.begin(), gyro_.end(), from,
                             [](double t, const GyroSample& s) { return t < s.stamp; });
  if (it == gyro_.begin() || it == gyro_.end() || gyro_.back().stamp < to) return std::nullopt;
  --it;  // the sample in force at `from`
  SO3d increment;
  double t = from;
  for (; it != gyro_.end() && t < to; ++it) {
    const double until = std::next(it) == gyro_.end() ? to : std::min(to, std::next(it)->stamp);
    increment = increment * SO3d::Exp(it->rate * (until - t));
    t = until;
  }
  return increment;
}

RadarOdometry::Prediction RadarOdometry::Predict(double stamp) const {
  const OdometryStep& last = steps_.back();
  Prediction p;
  p.dt = stamp - last.stamp;
  SO3d increment;
  if (const std::optional<SO3d> gyro = GyroIncrement(last.stamp, stamp)) {
    increment = *gyro;
    p.gyro = true;
  } else if (steps_.size() >= 2) {  // the last increment's yaw rate; roll and pitch held
    const OdometryStep& before = steps_[steps_.size() - 2];
    const double yaw_rate =
        (before.pose.rotation().Inverse() * last.pose.rotation()).Log().z() / (last.stamp - before.stamp);
    increment = SO3d::Exp(Eigen::Vector3d(0.0, 0.0, yaw_rate * p.dt));
  }
  p.increment = increment;
  // A vehicle keeps its velocity in its own frame: the last one, unrotated.
  p.velocity = last.velocity;
  p.velocity_covariance =
      last.velocity_covariance + std::pow(options_.acceleration_std * p.dt, 2) * Eigen::Matrix3d::Identity();
  return p;
}

SE3d RadarOdometry::PredictedPose(const Prediction& p, const Eigen::Vector3d& velocity) const {
  const SE3d& last = steps_.back().pose;
  return SE3d(last.rotation() * p.increment, last.translation() + last.rotation() * Displacement(p, velocity));
}

Eigen::Vector3d RadarOdometry::Displacement(const Prediction& p, const Eigen::Vector3d& velocity) {
  // The velocity of the new scan's frame, turned by half the increment: the
  // mean direction of travel over the interval, in the previous frame.
  return SO3d::Exp(0.5 * p.increment.Log()) * velocity * p.dt;
}

std::vector<std::size_t> RadarOdometry::MeasureVelocity(const RadarScan& scan, const Prediction* prediction,
                                                        OdometryStep& step) {
  std::vector<std::size_t> static_points;
  if (!scan.has_doppler) {
    step.reason = "no Doppler field: velocity predicted, every point matched";
    for (std::size_t i = 0; i < scan.points.size(); ++i) static_points.push_back(i);
    return static_points;
  }
  std::optional<VelocityGate> gate;
  if (prediction && last_measured_) {
    const OdometryStep& measured = steps_[*last_measured_];
    const double dt = scan.timestamp - measured.stamp;
    const double spread =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(measured.velocity_covariance).eigenvalues().maxCoeff();
    gate = VelocityGate{prediction->velocity,
                        std::max(options_.min_gate, options_.gate_sigmas *
                                                        std::sqrt(std::max(spread, 0.0) +
                                                                  std::pow(options_.acceleration_std * dt, 2)))};
  }
  const EgoVelocityResult ego = EstimateEgoVelocity(scan, options_.ego_velocity, gate);
  for (std::size_t i = 0; i < ego.inlier.size(); ++i) {
    if (ego.inlier[i]) static_points.push_back(i);
  }
  if (!ego.success || (!ego.zero_velocity && static_points.size() < options_.min_static_points)) {
    step.reason = ego.success ? "too few static points (" + std::to_string(static_points.size()) +
                                    "): velocity and pose predicted"
                              : "ego velocity: " + ego.reason + ": velocity and pose predicted";
    static_points.clear();
    return static_points;
  }
  step.velocity_measured = true;
  step.standstill = ego.zero_velocity;
  step.velocity = ego.velocity;
  step.velocity_covariance = ego.covariance;
  return static_points;
}

const OdometryStep& RadarOdometry::Register(const RadarScan& scan) {
  const auto start = std::chrono::steady_clock::now();
  if (!std::isfinite(scan.timestamp)) throw DataError("scan stamp is not finite");
  if (!steps_.empty() && !(scan.timestamp > steps_.back().stamp)) {
    throw DataError("scan stamps must increase: " + std::to_string(scan.timestamp) + " s after " +
                    std::to_string(steps_.back().stamp) + " s");
  }
  ValidateScan(scan, "scan at " + std::to_string(scan.timestamp) + " s");
  OdometryStep step;
  step.stamp = scan.timestamp;
  step.points = scan.points.size();
  std::optional<Prediction> prediction;
  if (!steps_.empty()) prediction = Predict(scan.timestamp);
  if (prediction) {
    step.velocity = prediction->velocity;
    step.velocity_covariance = prediction->velocity_covariance;
    step.gyro = prediction->gyro;
  }
  const std::vector<std::size_t> static_points = MeasureVelocity(scan, prediction ? &*prediction : nullptr, step);
  step.static_points = static_points.size();
  if (!prediction) {
    step.pose = options_.initial_pose;
  } else if (step.standstill) {
    step.pose = steps_.back().pose;  // standing: the pose holds
  } else {
    step.pose = PredictedPose(*prediction, step.velocity);
    if (static_points.size() >= options_.min_static_points) Match(scan, static_points, *prediction, step);
  }
  if (step.velocity_measured) last_measured_ = steps_.size();
  if (!step.standstill) UpdateMap(scan, static_points, step);
  step.active_gaussians = map_.gaussians();
  step.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  // Counted outside the step's time: the map changes on keyframes only.
  step.active_map_bytes = step.keyframe || steps_.empty() ? map_.MemoryBytes() : steps_.back().active_map_bytes;
  steps_.push_back(step);
  return steps_.back();
}

void RadarOdometry::Match(const RadarScan& scan, const std::vector<std::size_t>& static_points,
                          const Prediction& prediction, OdometryStep& step) {
  RadarScan matched;
  matched.timestamp = scan.timestamp;
  matched.has_doppler = scan.has_doppler;
  matched.has_rcs = scan.has_rcs;
  matched.points.reserve(static_points.size());
  for (const std::size_t i : static_points) matched.points.push_back(scan.points[i]);
  MatchOptions match = options_.match;
  if (options_.velocity_weight > 0.0) {
    VelocityPrior prior;
    prior.previous = steps_.back().pose;
    prior.displacement = Displacement(prediction, step.velocity);
    prior.sqrt_information = VelocitySqrtInformation(
        step.velocity_covariance, prediction.dt,
        options_.velocity_floor * options_.velocity_floor * Eigen::Matrix3d::Identity());
    prior.weight = options_.velocity_weight;
    match.matching.velocity = prior;
  }
  if (options_.rotation_weight > 0.0) {
    RotationPrior prior;
    prior.predicted = steps_.back().pose.rotation() * prediction.increment;
    const Eigen::Vector3d sigma = options_.rotation_rate_std_deg * (M_PI / 180.0 * prediction.dt);
    prior.sqrt_information = sigma.cwiseInverse().asDiagonal();
    prior.weight = options_.rotation_weight;
    match.matching.rotation = prior;
  }
  const ScanMatchingResult result = matcher_(map_, match)->Match(matched, map_.matching(), step.pose);
  step.iterations = result.iterations;
  step.final_cost = result.final_cost;
  step.converged = result.converged;
  const bool usable = result.pose.translation().allFinite() && result.n_geo >= options_.min_matched_points;
  if (!usable) {
    const std::string why = result.reason.empty() ? "too few points associated" : result.reason;
    step.reason = (step.reason.empty() ? "" : step.reason + "; ") + "matching: " + why + ": pose predicted";
    step.converged = false;
    return;
  }
  step.pose = result.pose;
  step.matched = true;
  step.information = result.information;
  step.velocity_information = result.velocity_information;
  step.rotation_information = result.rotation_information;
  if (!result.converged) step.reason = (step.reason.empty() ? "" : step.reason + "; ") + "matching: " + result.reason;
}

void RadarOdometry::UpdateMap(const RadarScan& scan, const std::vector<std::size_t>& static_points,
                              OdometryStep& step) {
  if (static_points.empty()) return;
  if (!steps_.empty()) {
    const SE3d moved = last_keyframe_.Inverse() * step.pose;
    const bool far = moved.translation().norm() >= options_.keyframe_distance;
    const bool turned = moved.rotation().Log().norm() >= options_.keyframe_angle_deg * M_PI / 180.0;
    if (!far && !turned) return;
  }
  std::vector<Eigen::Vector3d> points;
  std::vector<double> rcs;
  points.reserve(static_points.size());
  for (const std::size_t i : static_points) {
    points.push_back(step.pose * scan.points[i].position);
    if (scan.has_rcs) rcs.push_back(scan.points[i].rcs);
  }
  map_.Insert(points, rcs, step.pose);
  map_.Evict(step.pose.translation());
  last_keyframe_ = step.pose;
  step.keyframe = true;
}

Trajectory RadarOdometry::trajectory() const {
  Trajectory trajectory;
  for (const OdometryStep& step : steps_) trajectory.Append(step.stamp, step.pose);
  return trajectory;
}

}  // namespace radargauss
