// SPDX-License-Identifier: BSD-3-Clause
// The reference radar's motion and map for the calibration of a rig, offline
// and online (docs/design/rig.md, "Calibration of a rig", "Online
// calibration"): its velocity, angular velocity and their rates at any
// instant of its drive, the angular velocity from the gyro where an IMU's
// window ran; its map and the residual of a point against it. Internal to src/odometry.
#pragma once

#include <algorithm>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/crs_matrix.h>
#include <ceres/problem.h>

#include <Eigen/Core>

#include "radargauss/core/types.hpp"
#include "radargauss/lie/se3.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/pipeline.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/residuals/rig_doppler_residual.hpp"

namespace radargauss::rig_calibration {

// The reference radar's motion between its odometry's scans: the velocity
// linear between scans, the angular velocity of each interval linear between
// the intervals' midpoints, the pose at a constant twist over its interval.
class ReferenceTrack {
 public:
  explicit ReferenceTrack(const std::vector<OdometryStep>& steps) {
    for (const OdometryStep& step : steps) {
      stamps_.push_back(step.stamp);
      poses_.push_back(step.pose);
      velocities_.push_back(step.velocity);
    }
    for (std::size_t k = 0; k + 1 < stamps_.size(); ++k) {
      const double dt = stamps_[k + 1] - stamps_[k];
      twists_.push_back((poses_[k].Inverse() * poses_[k + 1]).Log() / dt);
      midpoints_.push_back(0.5 * (stamps_[k] + stamps_[k + 1]));
    }
  }

  bool Covers(double t) const { return midpoints_.size() >= 2 && t >= midpoints_.front() && t < midpoints_.back(); }

  // The angular velocity from a gyro's rates (the reference's frame, the
  // body's clock, bias removed) where they cover t: their mean within
  // kGyroSpan of t, without the lag of rates differenced from the poses.
  void UseGyro(std::vector<GyroSample> rates) { gyro_ = std::move(rates); }

  ReferenceMotion Motion(double t) const {
    ReferenceMotion motion;
    const std::size_t k = Interval(stamps_, t);
    const double dt = stamps_[k + 1] - stamps_[k], s = (t - stamps_[k]) / dt;
    motion.velocity = (1.0 - s) * velocities_[k] + s * velocities_[k + 1];
    motion.acceleration = (velocities_[k + 1] - velocities_[k]) / dt;
    const std::size_t j = Interval(midpoints_, t);
    const double dm = midpoints_[j + 1] - midpoints_[j], r = (t - midpoints_[j]) / dm;
    const Eigen::Vector3d w0 = twists_[j].tail<3>(), w1 = twists_[j + 1].tail<3>();
    motion.angular_velocity = (1.0 - r) * w0 + r * w1;
    motion.angular_acceleration = (w1 - w0) / dm;
    if (const std::optional<Eigen::Vector3d> rate = GyroRate(t)) motion.angular_velocity = *rate;
    return motion;
  }

  SE3d Pose(double t) const {
    const std::size_t k = Interval(stamps_, t);
    return poses_[k] * SE3d::Exp(twists_[k] * (t - stamps_[k]));
  }

 private:
  // The k with times[k] <= t < times[k + 1], clamped to the intervals.
  static std::size_t Interval(const std::vector<double>& times, double t) {
    const auto upper = std::upper_bound(times.begin(), times.end(), t);
    const std::size_t k = std::size_t(std::max<std::ptrdiff_t>(1, upper - times.begin())) - 1;
    return std::min(k, times.size() - 2);
  }

  static constexpr double kGyroSpan = 0.01;  // s
  std::optional<Eigen::Vector3d> GyroRate(double t) const {
    if (gyro_.empty() || t < gyro_.front().stamp || t > gyro_.back().stamp) return std::nullopt;
    const auto by_stamp = [](const GyroSample& a, double b) { return a.stamp < b; };
    auto it = std::lower_bound(gyro_.begin(), gyro_.end(), t - kGyroSpan, by_stamp);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (; it != gyro_.end() && it->stamp <= t + kGyroSpan; ++it, ++count) sum += it->rate;
    if (count == 0) return std::nullopt;
    return Eigen::Vector3d(sum / double(count));
  }

  std::vector<double> stamps_, midpoints_;
  std::vector<GyroSample> gyro_;
  std::vector<SE3d> poses_;
  std::vector<Eigen::Vector3d> velocities_;
  std::vector<Eigen::Matrix<double, 6, 1>> twists_;
};

// The gyro's rates in the reference radar's frame on the body's clock, each
// at its interval's middle (a sample holds the mean rate to the next), less
// the window's gyro bias at the nearest state; none where the window never
// started or dropped the IMU.
std::vector<GyroSample> GyroRatesOf(const InertialMotion& inertial, std::vector<ImuSample> imu);

// A problem's Gauss-Newton information over the 7 tangent directions of a
// radar's rotation, translation and clock, H = J^T J, and the spread of its
// gradients clustered by scan, B = sum_s g_s g_s^T (g_s = J_s^T r_s): a scan's
// residuals share its reference motion's errors, so they are not counted as
// independent (docs/design/rig.md, "Calibration of a rig").
struct ClusteredMoments {
  Eigen::Matrix<double, 7, 7> information, spread;
};
// `residuals` in the order of their scans (scan_of); none when the problem's
// Jacobian has other than 7 columns.
std::optional<ClusteredMoments> ClusteredByScan(ceres::Problem& problem, const std::vector<double*>& blocks,
                                                const std::vector<ceres::ResidualBlockId>& residuals,
                                                const std::vector<std::size_t>& scan_of);

// A calibration's small problem solved: Levenberg-Marquardt on dense QR, one thread.
void SolveDense(ceres::Problem& problem, int max_iterations);

// The reference radar's map, with when the reference saw each Gaussian:
// its odometry drifts, and a point matched to what the reference saw long
// before carries that drift into the extrinsic.
struct ReferenceMap {
  GaussianIndex index;
  std::vector<double> first_seen, last_seen;  // s, the body's clock

  // The residual of a radar's point (its frame) seen at t against the
  // Gaussian it meets within `gate` (Mahalanobis) that the reference saw
  // within `max_age` of t: the Gaussian in the reference's frame at t (mean
  // T^-1 mu, sqrt information L^T R); null when it meets none.
  ceres::CostFunction* PointCost(const Eigen::Vector3d& point, double t, const SE3d& extrinsic,
                                 const SE3d& world_from_reference, const SE3d& reference_from_world,
                                 const ReferenceMotion& motion, double gate, double max_age) const;
};

// The map of the reference's scans at its poses T_world_ref (stamps on the body's clock).
ReferenceMap BuildReferenceMap(const std::vector<RadarScan>& scans, const std::vector<SE3d>& poses,
                               const MapOptions& options);

}  // namespace radargauss::rig_calibration
