// SPDX-License-Identifier: BSD-3-Clause
// Radar ego velocity from one scan's Doppler (Doer and Trommer, "An EKF Based
// Approach to Radar Inertial Odometry", MFI 2020: RANSAC + least squares, as
// in their radar_ego_velocity_estimator). Static points satisfy
// v_d = -u . v_sensor (conventions.hpp), so each point gives one row of
// H v = v_d with H_i = -u_i^T.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/core/options.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

struct EgoVelocityOptions {
  double min_range = 0.25;                // m, range gate
  double max_range = 100.0;               // m
  double outlier_probability = 0.4;       // RANSAC: expected outlier share
  double success_probability = 0.9999;    // RANSAC: wanted chance of one clean draw
  double inlier_threshold = 0.15;         // m/s, |v_d - H v|
  double zero_velocity_threshold = 0.05;  // m/s, 75th percentile of |v_d| below it: standing
  double zero_velocity_sigma = 0.025;     // m/s, std reported when standing
  std::uint32_t seed = 1;                 // RANSAC draws are deterministic for a seed
  // > 0 (m): draws take points of three distinct voxels of this edge and a
  // hypothesis's support is the number of voxels its inliers occupy, so that
  // a large close object (a car ahead) cannot outvote the wider static
  // world; 0: points drawn uniformly, support = the number of inliers.
  double consensus_voxel = 0.0;
};

// Its options (options.hpp), as odometry names them (ego_*, seed).
const OptionTable<EgoVelocityOptions>& EgoVelocityOptionTable();

struct EgoVelocityResult {
  bool success = false;
  std::string reason;                                    // why it failed; empty on success
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();    // sensor velocity, radar frame, m/s
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // sigma^2 (H^T H)^-1
  std::vector<bool> inlier;                              // per input point: static and in the range gate
  bool zero_velocity = false;                            // the zero-velocity branch decided
  int ransac_iterations = 0;
};

// RANSAC iterations for 3-point draws: log(1 - p_success) / log(1 - (1 - p_outlier)^3).
int RansacIterations(double outlier_probability, double success_probability);

// A predicted sensor velocity (a motion model's) and how far from it an
// estimate may lie: hypotheses beyond the gate, the standstill branch
// included, are not taken, so a moving object that fills the view is not
// taken for the static world.
struct VelocityGate {
  Eigen::Vector3d predicted = Eigen::Vector3d::Zero();  // m/s, radar frame
  double gate = 1.0;                                    // m/s
  bool Admits(const Eigen::Vector3d& velocity) const { return (velocity - predicted).norm() <= gate; }
};
// The gate's width around a velocity measured `dt` ago with covariance S:
// gate_sigmas sqrt(lambda_max(S) + (acceleration_std dt)^2), at least min_gate.
double VelocityGateWidth(const Eigen::Matrix3d& covariance, double dt, double gate_sigmas, double acceleration_std,
                         double min_gate);

EgoVelocityResult EstimateEgoVelocity(const RadarScan& scan, const EgoVelocityOptions& options = {},
                                      const std::optional<VelocityGate>& gate = std::nullopt);

}  // namespace radargauss
