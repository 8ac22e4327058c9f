// SPDX-License-Identifier: BSD-3-Clause
// The inertial window's problem (solvers/inertial_window.hpp): its states,
// the terms that end at each, the global blocks (extrinsic, tilt, clock
// offset, elevation bias), the bounds of the clock offset, the Ceres problem
// they make and the calibration gate on it. InertialWindow's public steps
// (src/solvers/inertial_window.cpp) add, solve and marginalise them. Internal
// to src/solvers.
#pragma once

#include <ceres/problem.h>

#include <cmath>
#include <deque>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "radargauss/lie/manifold.hpp"
#include "radargauss/residuals/imu_preintegration.hpp"
#include "radargauss/residuals/radar_inertial_residuals.hpp"
#include "radargauss/solvers/inertial_window.hpp"
#include "radargauss/solvers/marginalization.hpp"

namespace radargauss {

namespace inertial_window {

// The first state's prior on the elevation bias (std).
constexpr double kElevationBiasPrior = 2.0 * M_PI / 180.0;  // rad: a radar's bias is a fraction of a degree

using CostPointer = std::shared_ptr<ceres::CostFunction>;

}  // namespace inertial_window

// One state and the terms that end at it.
struct InertialWindow::Node {
  double stamp = 0.0;
  Eigen::Vector4d rotation = Eigen::Vector4d(0, 0, 0, 1);  // R_world_imu, x y z w
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 9, 1> motion = Eigen::Matrix<double, 9, 1>::Zero();  // v, b_g, b_a
  std::optional<ImuPreintegration> from_previous;             // the IMU between the node before and this one
  inertial_window::CostPointer imu, pose, velocity, vehicle;  // terms on this node (imu: from the one before)
  // The measurements, kept to make their terms again at a new clock offset.
  std::optional<std::pair<SE3d, Eigen::Matrix<double, 6, 6>>> pose_measurement;  // pose, W
  struct VelocityMeasurement {
    Eigen::Vector3d velocity;
    Eigen::Matrix3d sqrt_information;
    double elevation_bias_removed = 0.0;  // rad
  };
  std::optional<VelocityMeasurement> velocity_measurement;
  std::vector<std::pair<inertial_window::CostPointer, std::vector<double*>>> first_priors;  // the first state's

  InertialState State() const {
    InertialState s;
    s.stamp = stamp;
    s.pose = SE3d(SO3d::FromXyzw(rotation.data()), position);
    s.velocity = motion.segment<3>(kMotionVelocity);
    s.bias.gyro = motion.segment<3>(kMotionGyroBias);
    s.bias.accel = motion.segment<3>(kMotionAccelBias);
    return s;
  }
  ImuBias Bias() const { return {motion.segment<3>(kMotionGyroBias), motion.segment<3>(kMotionAccelBias)}; }
};

struct InertialWindow::Impl {
  std::deque<Node> nodes;  // a deque keeps the blocks' addresses as states come and go
  std::vector<ImuSample> imu;
  SO3Manifold so3;
  Eigen::Vector4d extrinsic_rotation;  // R_imu_radar, x y z w
  Eigen::Vector3d extrinsic_translation;
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();
  double clock_offset[1] = {0.0};    // t_d: the block
  double clock_linearisation = 0.0;  // t_0: where the samples were read
  bool clock_held = false;           // held at a bound since the last solve: every term read again
  double elevation_bias[1] = {0.0};  // b: the block
  std::shared_ptr<MarginalizationPrior> prior;

  // The IMU's reading in force at a scan's stamp, at the clock offset t_0.
  ImuAtScan ImuAt(double stamp) const;
  void MakeRadarTerms(Node& node) const;
  // The blocks the solvers move, in a fixed order.
  std::vector<double*> VariableBlocks(const InertialWindowOptions& options);
  std::vector<double*> GlobalBlocks(const InertialWindowOptions& options);
  // Where the clock offset may lie with the window's oldest state and a
  // newest at `newest`: within [-kMaxClockOffset, kMaxClockOffset] and
  // within the IMU's samples at both ends, so that every term can be
  // integrated at it. Empty (lowest > highest) when the data leaves no room.
  std::pair<double, double> ClockOffsetBounds(double newest) const;
  // Before a state at `stamp` is added: an offset at which its IMU interval
  // would pass the IMU's last sample is held at the largest the data covers
  // (when there is room; otherwise the interval is refused as the data's
  // fault), and the next Solve reads every term again at it.
  void HoldClockOffsetFor(double stamp);
  // After a solve: the estimate put back within its bounds; whether it had left them.
  bool HoldClockOffsetInBounds();
  // Every term of the window in `problem`; the ids of those on the oldest state in `oldest_terms`.
  void Build(ceres::Problem& problem, const InertialWindowOptions& options,
             std::vector<ceres::ResidualBlockId>* oldest_terms);
  // The calibration gate: each estimated calibration block's observation,
  // and with options.calibration_gate a term in `problem` holding it along
  // what the data do not observe.
  CalibrationObservation ObserveCalibration(ceres::Problem& problem, const InertialWindowOptions& options,
                                            std::vector<std::unique_ptr<ceres::CostFunction>>& holds);
};

}  // namespace radargauss
