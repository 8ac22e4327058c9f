// SPDX-License-Identifier: BSD-3-Clause
// The front door: the main jobs in a few calls, without a Ceres header (the
// solvers keep Ceres behind the library). Simulate or load a sequence, build
// a Gaussian-RCS map from scans and reference poses, match a scan against it,
// run odometry on a map built on the way (with an IMU or without), run SLAM,
// evaluate a trajectory. docs/design.md explains each step.
//
//   const Sequence sequence = LoadSequence(sequence_options);
//   const MatchingMap map(BuildMap(sequence));
//   const ScanMatchingResult match = Match(scan, map, initial_guess);
//   const RadarOdometry odometry = Odometry(sequence);
//   const auto slam = Slam(sequence);  // slam->trajectory()
#pragma once

#include <memory>
#include <vector>

#include "radargauss/core/error.hpp"
#include "radargauss/experiment/evaluation.hpp"
#include "radargauss/io/sequence.hpp"
#include "radargauss/lie/se3.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/pipeline.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "radargauss/slam/radar_slam.hpp"
#include "radargauss/solvers/factory.hpp"
#include "radargauss/core/trajectory.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

// The pipeline of `radargauss build-map`: Doppler filter, merged static
// cloud, Gaussians, RCS models. Needs sequence.poses. Throws DataError.
GaussianMap BuildMap(const Sequence& sequence, const MapOptions& options = {});
// The same from scans and their poses T_world_radar (one per scan).
GaussianMap BuildMap(const std::vector<RadarScan>& scans, const std::vector<SE3d>& poses,
                     const MapOptions& options = {});

// Matches `scan` against `map` from `initial` (T_world_radar) with the solver
// of options.solver: minimises eq. 2 coarse to fine. Throws
// std::invalid_argument for bad options; a match that fails says why in
// result.reason.
ScanMatchingResult Match(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                         const MatchOptions& options = {});

// `radargauss odometry`: every scan of `sequence` registered in order on a
// map built on the way (docs/design/odometry.md, "Odometry"); its steps, trajectory()
// and map() hold the run. Throws DataError for stamps that do not increase.
RadarOdometry Odometry(const Sequence& sequence, const OdometryOptions& options = {});

// `radargauss odometry --imu`: the same with the IMU's samples (on the scans'
// clock) and T_radar_imu, its motion model named by options.fusion
// (docs/design/odometry.md, "Radar-inertial odometry"; InertialMotionOf
// gives the window). Throws DataError for no samples or when the IMU does
// not cover the scans.
RadarOdometry InertialOdometry(const Sequence& sequence, std::vector<ImuSample> imu, const SE3d& radar_from_imu,
                               const OdometryOptions& odometry = {}, const RadarInertialOptions& options = {});

// `radargauss slam`: every scan of `sequence` through SLAM, finished
// (docs/design/slam.md, "SLAM"); its trajectory(), keyframes() and loops()
// hold the run.
std::unique_ptr<RadarSlam> Slam(const Sequence& sequence, const SlamOptions& options = {});

}  // namespace radargauss
