// SPDX-License-Identifier: BSD-3-Clause
// An IMU made for a recorded drive (docs/design/simulator.md, "An IMU from a
// reference"): the reference's poses smoothed into a twice-differentiable
// motion, and the simulator's IMU model (rates, specific force, turn-on
// biases, random walks, white noise, clock offset, mounting) sampled along it.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "radargauss/core/trajectory.hpp"
#include "radargauss/io/imu.hpp"
#include "radargauss/simulator/simulator.hpp"

namespace radargauss {

// The IMU's samples, stamped on its clock, and its true biases at each.
struct SimulatedImu {
  std::vector<ImuSample> samples;
  std::vector<ImuBias> bias;
};

// `count` samples every 1 / config.imu_rate_hz along world_from_imu(t)
// (T_world_imu, t in s from config.start_time on the true clock, gravity
// along the world's -z), with config's imu_* noise, biases and clock offset
// drawn from a generator seeded by config.seed. world_from_imu is evaluated
// up to 1 ms around [0, count / rate].
SimulatedImu SimulateImuAlong(const std::function<SE3d(double)>& world_from_imu, std::size_t count,
                              const SimulationConfig& config);

// config's imu_roll/pitch/yaw_deg and imu_x/y/z: T_vehicle_imu.
SE3d ImuOnVehicle(const SimulationConfig& config);

// imu.txt, imu_extrinsic.txt (T_radar_imu; a rig's T_body_imu, `host`
// "body") and the true imu_biases.txt in `dir` (io/imu.hpp's formats), each
// written whole or not at all.
void WriteImuFiles(const std::string& dir, const SimulatedImu& imu, const SE3d& radar_from_imu,
                   const std::string& host = "radar");

// A smooth motion through a reference: uniform cubic B-splines fitted by
// least squares to its positions and to its roll, pitch and (unwrapped) yaw
// (R = Rz(yaw) Ry(pitch) Rx(roll)), a knot every knot_spacing seconds,
// `smoothing` weighing the control points' second differences. Beyond the
// reference's ends it goes on at its end velocity and rate.
class SmoothTrajectory {
 public:
  // Throws DataError for fewer than two knots' worth of poses, a knot
  // spacing not above zero or a reference that pitches to +-90 deg.
  SmoothTrajectory(const Trajectory& reference, double knot_spacing, double smoothing);
  SE3d operator()(double time) const;  // on the reference's clock
  double start() const { return start_; }
  double end() const { return end_; }
  // The fit's rms residual over the reference: position (m), rotation (rad).
  double position_rms() const { return position_rms_; }
  double rotation_rms() const { return rotation_rms_; }

 private:
  Eigen::Matrix<double, 6, 1> Channels(double time) const;  // x y z roll pitch yaw inside [start, end]
  SE3d Pose(const Eigen::Matrix<double, 6, 1>& channels) const;
  double start_ = 0.0, end_ = 0.0, spacing_ = 1.0;
  Eigen::MatrixXd control_;  // one row per control point, one column per channel
  double position_rms_ = 0.0, rotation_rms_ = 0.0;
};

}  // namespace radargauss
