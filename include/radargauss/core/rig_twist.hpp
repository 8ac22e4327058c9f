// SPDX-License-Identifier: BSD-3-Clause
// The twist of a rig of radars from their Doppler (docs/design/rig.md, "The
// rig's twist"). Radar i sits at T_body_radar_i = (R_i, t_i) and moves with
// v_i = R_i^T (v + w x t_i) in its frame, v and w the body's velocity and
// angular velocity in the body frame. A static point seen in direction u
// (radar frame) measures v_d = -u . v_i (conventions.hpp), which is linear in
// the twist: v_d = -b^T v - (t_i x b)^T w with b = R_i u. All radars' points
// together give one system H [v; w] = y; RANSAC over the rig's points finds
// the static ones and least squares on them the twist, with its covariance.
//
// What the rig observes depends on its lever arms: one radar (or radars at
// one place) gives the three components of v + w x t only; radars on a line
// leave the rotation about that line unobserved (two radars on the vehicle's
// axis: the roll rate); three lever arms not on a line give all six. The
// estimate states the directions it observed (`rank`, `observed`) and leaves
// the others at zero with no covariance.
//
//   RigTwist twist = EstimateRigTwist({{&front_scan, T_body_front}, {&rear_scan, T_body_rear}});
//   if (twist.success) yaw_rate = twist.angular_velocity.z();
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/core/doppler.hpp"
#include "radargauss/core/types.hpp"
#include "radargauss/lie/se3.hpp"

namespace radargauss {

// One radar's scan and where the radar sits on the body.
struct RigScan {
  const RadarScan* scan = nullptr;
  SE3d body_from_radar;  // T_body_radar
};

struct RigTwistOptions {
  // Each radar's range gate, RANSAC probabilities, inlier threshold and seed
  // (the consensus voxel and the zero-velocity branch are single-radar only).
  EgoVelocityOptions doppler;
  // A direction of the twist whose singular value of H, relative to the
  // largest, lies below this is unobserved.
  double min_relative_singular_value = 1e-4;
  // A gate around a predicted velocity v (the body's frame and origin):
  // hypotheses outside it do not count, and a twist outside it fails (the
  // odometry's prediction, as for one radar; none: no gate). Where the rig
  // leaves a rotation unobserved, put the origin at a radar, where v is.
  std::optional<VelocityGate> gate;
  // The same for the angular velocity w (rad/s, body frame).
  std::optional<VelocityGate> angular_gate;
};

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct RigTwist {
  bool success = false;
  std::string reason;                                          // why it failed; empty on success
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          // m/s, body frame
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // rad/s, body frame
  // Of [v; w]: sigma^2 (H^T H)^+ on the observed directions, sigma^2 from the
  // inliers' residuals; zero on the unobserved ones.
  Matrix6d covariance = Matrix6d::Zero();
  int rank = 0;                           // observed directions of [v; w]
  Matrix6d observed = Matrix6d::Zero();   // the projector onto them (identity when rank is 6)
  std::vector<std::vector<bool>> inlier;  // per radar, per point: static and in the range gate
  int ransac_iterations = 0;
};

// The velocity (m/s, its own frame) of the radar at `body_from_radar` when
// the body moves with v and w (body frame): R^T (v + w x t).
Eigen::Vector3d RigRadarVelocity(const SE3d& body_from_radar, const Eigen::Vector3d& v, const Eigen::Vector3d& w);
// The Doppler (m/s, positive receding) that a static point at `position`
// (radar frame) shows to the radar at `body_from_radar` when the body moves
// with velocity v and angular velocity w (body frame).
double RigDoppler(const Eigen::Vector3d& position, const SE3d& body_from_radar, const Eigen::Vector3d& v,
                  const Eigen::Vector3d& w);
// Its row of H: d v_d / d [v; w].
Eigen::Matrix<double, 1, 6> RigDopplerJacobian(const Eigen::Vector3d& position, const SE3d& body_from_radar);

// The directions of the angular velocity (body frame, unit columns) that no
// Doppler of radars at these mountings observes, whatever they see: all
// three when the radars share one place (or there is one), the line through
// them when they lie on one, none otherwise.
Eigen::Matrix3Xd UnobservedRotations(const std::vector<SE3d>& body_from_radars);

// Throws std::invalid_argument for a scan that is null. A radar whose scan
// has no Doppler adds no rows; fewer gated points than the rank fails.
RigTwist EstimateRigTwist(const std::vector<RigScan>& scans, const RigTwistOptions& options = {});

}  // namespace radargauss
