// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/mounting.hpp"

#include <cmath>
#include <stdexcept>

#include "radargauss/core/conventions.hpp"
#include "radargauss/core/stats.hpp"

namespace radargauss {

namespace {

// 1.4826 x the median absolute deviation from `median`: a robust std.
double Spread(const std::vector<double>& values, double median) {
  std::vector<double> deviations;
  for (const double v : values) deviations.push_back(std::abs(v - median));
  return 1.4826 * Median(deviations);
}

}  // namespace

const OptionTable<MountingOptions>& MountingOptionTable() {
  using O = MountingOptions;
  static const OptionTable<O> table = {
      RADARGAUSS_OPTION(O, "min_speed", min_speed)
          .Above(0.0)
          .Unit("m/s")
          .Help("slower scans say little about the direction of travel"),
      RADARGAUSS_OPTION(O, "max_yaw_rate", max_yaw_rate_deg)
          .Above(0.0)
          .Unit("deg/s")
          .Help("turning adds the lever arm's lateral velocity"),
      RADARGAUSS_OPTION(O, "min_scans", min_scans).AtLeast(1).Help("straight scans at speed needed for an estimate"),
  };
  return table;
}

void ValidateOptions(const MountingOptions& o) { CheckOptions(MountingOptionTable(), o); }

SO3d Mounting::vehicle_from_radar() const { return VehicleFromRadar(Eigen::Vector3d(0.0, pitch_deg, yaw_deg)); }

std::optional<Mounting> EstimateMounting(const std::vector<OdometryStep>& steps, const MountingOptions& options) {
  ValidateOptions(options);
  std::vector<double> pitch, yaw;
  for (std::size_t k = 1; k < steps.size(); ++k) {
    const OdometryStep& step = steps[k];
    const Eigen::Vector3d& v = step.velocity;
    if (!step.velocity_measured || v.norm() < options.min_speed) continue;
    // A turn adds the lever arm's velocity sideways: the elevation holds, the azimuth not.
    // The direction of travel in the radar frame is R_vehicle_radar^T e_x =
    // (cos p cos y, -sin y, sin p cos y).
    pitch.push_back(std::atan2(v.z(), v.x()) / kRadiansPerDegree);
    const double dt = step.stamp - steps[k - 1].stamp;
    const SO3d turn = steps[k - 1].pose.rotation().Inverse() * step.pose.rotation();
    if (!(dt > 0.0) || std::abs(turn.Log().z()) / dt > options.max_yaw_rate_deg * kRadiansPerDegree) continue;
    yaw.push_back(std::atan2(-v.y(), std::hypot(v.x(), v.z())) / kRadiansPerDegree);
  }
  if (yaw.size() < options.min_scans) return std::nullopt;
  Mounting mounting;
  mounting.pitch_deg = Median(pitch);
  mounting.yaw_deg = Median(yaw);
  mounting.pitch_spread_deg = Spread(pitch, mounting.pitch_deg);
  mounting.yaw_spread_deg = Spread(yaw, mounting.yaw_deg);
  mounting.pitch_scans = pitch.size();
  mounting.yaw_scans = yaw.size();
  return mounting;
}

Trajectory Levelled(const Trajectory& trajectory, const Mounting& mounting) {
  const SE3d level(mounting.vehicle_from_radar(), Eigen::Vector3d::Zero());
  std::vector<StampedPose> poses;
  for (const StampedPose& p : trajectory) poses.push_back({p.time, level * p.pose});
  return Trajectory(std::move(poses));
}

}  // namespace radargauss
