// SPDX-License-Identifier: BSD-3-Clause
// The odometry's prediction (docs/design/odometry.md, "Odometry"): the
// motion since the last scan from its velocity and the motion model's
// rotation (or the last yaw rate, or a rig's measured rates), and the
// velocity and rotation terms it gives the scan's match.
#include <cmath>

#include "radargauss/odometry/radar_odometry.hpp"

namespace radargauss {

// rad/s: the least std of a measured yaw rate in the rotation term (a rig's
// rates are measured at the interval's ends, its increment is trapezoidal).
constexpr double kMeasuredRateFloor = 0.005;

void RadarOdometry::PredictFromRates(const MeasuredRate& before, const MeasuredRate& now, Prediction& p) const {
  // The rates measured at both ends of the interval, trapezoidal: the turn
  // about the vehicle's vertical, roll and pitch held as without them; with
  // `all`, every rate (a rig's roll and pitch rates come from elevations).
  const Eigen::Vector3d rate = 0.5 * (before.value + now.value);
  const Eigen::Matrix3d covariance = 0.25 * (before.covariance + now.covariance);
  if (now.all) {
    p.increment = SO3d::Exp(rate * p.dt);
    p.increment_std = covariance.diagonal().cwiseSqrt() * p.dt;
  } else {
    const Eigen::Vector3d up = vehicle_from_radar_.Inverse() * Eigen::Vector3d::UnitZ();
    p.increment = SO3d::Exp(up * (rate.dot(up) * p.dt));
    p.yaw_std = std::sqrt(up.dot(covariance * up)) * p.dt;
  }
  p.gyro = true;
}

RadarOdometry::Prediction RadarOdometry::Predict(double stamp) const {
  const MotionState& last = *state_;
  Prediction p;
  p.dt = stamp - last.stamp;
  SO3d increment;
  if (const std::optional<SO3d> gyro = motion_->Rotation(last.stamp, stamp)) {
    increment = *gyro;
    p.gyro = true;
  } else if (last.before) {  // the last increment's yaw rate about the vehicle's vertical; roll and pitch held
    const auto& [before_stamp, before_pose] = *last.before;
    const Eigen::Vector3d up = vehicle_from_radar_.Inverse() * Eigen::Vector3d::UnitZ();
    const double yaw_rate =
        (before_pose.rotation().Inverse() * last.pose.rotation()).Log().dot(up) / (last.stamp - before_stamp);
    increment = SO3d::Exp(up * (yaw_rate * p.dt));
  }
  p.increment = increment;
  // A vehicle keeps its velocity in its own frame: the last one, unrotated.
  p.velocity = last.velocity;
  p.velocity_covariance =
      last.velocity_covariance + std::pow(options_.acceleration_std * p.dt, 2) * Eigen::Matrix3d::Identity();
  return p;
}

SE3d RadarOdometry::PredictedPose(const Prediction& p, const Eigen::Vector3d& velocity) const {
  const SE3d& last = state_->pose;
  return SE3d(last.rotation() * p.increment, last.translation() + last.rotation() * Displacement(p, velocity));
}

Eigen::Vector3d RadarOdometry::Displacement(const Prediction& p, const Eigen::Vector3d& velocity) {
  // The velocity of the new scan's frame, turned by half the increment: the
  // mean direction of travel over the interval, in the previous frame.
  return SO3d::Exp(0.5 * p.increment.Log()) * velocity * p.dt;
}

ScanPriors RadarOdometry::PriorsOf(const Prediction& prediction, const Velocity& velocity) const {
  ScanPriors priors;
  if (options_.velocity_weight > 0.0) {
    VelocityPrior prior;
    prior.previous = state_->pose;
    prior.displacement = Displacement(prediction, velocity.value);
    const double vertical =
        options_.velocity_vertical_floor > 0.0 ? options_.velocity_vertical_floor : options_.velocity_floor;
    const Eigen::Vector3d floor(options_.velocity_floor, options_.velocity_floor, vertical);
    prior.sqrt_information =
        VelocitySqrtInformation(velocity.covariance, prediction.dt, floor.cwiseAbs2().asDiagonal());
    prior.weight = options_.velocity_weight;
    priors.velocity = prior;
  }
  if (options_.rotation_weight > 0.0) {
    RotationPrior prior;
    prior.predicted = state_->pose.rotation() * prediction.increment;
    Eigen::Vector3d sigma = options_.rotation_rate_std_deg * (M_PI / 180.0 * prediction.dt);
    // A measured yaw increment's own std where it is tighter.
    if (prediction.yaw_std)
      sigma.z() = std::min(sigma.z(), std::max(*prediction.yaw_std, kMeasuredRateFloor * prediction.dt));
    // About the vehicle's axes: the residual Log(R_pred^T R) turned into them.
    prior.sqrt_information = sigma.cwiseInverse().asDiagonal() * vehicle_from_radar_.Matrix();
    prior.weight = options_.rotation_weight;
    priors.rotation = prior;
  }
  return priors;
}

}  // namespace radargauss
