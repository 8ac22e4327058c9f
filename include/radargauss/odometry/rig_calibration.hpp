// SPDX-License-Identifier: BSD-3-Clause
// The offline calibration of a rig (docs/design/rig.md, "Calibration of a
// rig"): each radar's extrinsic against the reference radar (the first) and
// its clock offset, from a drive. The reference radar's odometry gives the
// body's motion and a map; every other radar's static points then hold two
// kinds of residual on its extrinsic T_ref_radar and its clock offset:
//
// - its Doppler against the reference's motion at the scan's time, moved
//   through the lever arm (residuals/rig_doppler_residual.hpp);
// - its points against the reference's map, at the reference's pose at the
//   scan's time (the geometric residual of eq. 1, the Gaussian brought into
//   the reference's frame).
//
// Rounds re-associate the points and re-read the motion at the new clock.
// Each estimate comes with its standard deviation, or is reported unobserved
// where the drive leaves it open (no turn: no lever arm along the turn's axis).
//
//   const RigCalibration calibration = CalibrateRig(rig, scans);
//   WriteRig(path, calibration.rig);
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/core/options.hpp"
#include "radargauss/core/trajectory.hpp"
#include "radargauss/core/types.hpp"
#include "radargauss/io/imu.hpp"
#include "radargauss/io/rig.hpp"
#include "radargauss/lie/se3.hpp"
#include "radargauss/map/pipeline.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/odometry/radar_odometry.hpp"

namespace radargauss {

struct RigCalibrationOptions {
  bool estimate_rotation = true;
  bool estimate_translation = true;
  bool estimate_clock_offset = true;
  double doppler_std = 0.05;              // m/s: a Doppler residual's sigma
  double map_weight = 1.0;                // of the map residuals against the Doppler's (0: Doppler alone)
  std::size_t points_per_scan = 40;       // static points of each scan used, spread over the scan
  int rounds = 8;                         // re-associations and re-readings of the motion
  double loss_scale = 2.0;                // Huber, in sigmas (and Mahalanobis distance)
  double map_max_age = 2.0;               // s: a point meets the Gaussians the reference saw within this of its scan
  double association_gate = 3.0;          // Mahalanobis distance of a point to its Gaussian
  double min_relative_eigenvalue = 1e-6;  // of the information: smaller directions are unobserved
  OdometryOptions reference;              // the reference radar's odometry
  MapOptions map;                         // the reference radar's map, at its odometry's poses
};
// Its options (options.hpp); ValidateOptions throws std::invalid_argument naming the bad one.
const OptionTable<RigCalibrationOptions>& RigCalibrationOptionTable();
void ValidateOptions(const RigCalibrationOptions& options);

// One radar's calibration. Standard deviations are of the rotation (rad,
// about the reference's axes), the translation (m) and the clock offset (s);
// infinite where the drive does not observe the direction.
struct RadarCalibration {
  std::string name;
  SE3d body_from_radar;       // calibrated (the reference: as given)
  double clock_offset = 0.0;  // s, calibrated
  Eigen::Vector3d rotation_std = Eigen::Vector3d::Zero();
  Eigen::Vector3d translation_std = Eigen::Vector3d::Zero();
  double clock_offset_std = 0.0;
  std::size_t scans = 0;           // scans within the reference's drive
  std::size_t doppler_points = 0;  // residuals of the last round
  std::size_t map_points = 0;
};

struct RigCalibration {
  Rig rig;                               // the given rig, its mountings and clocks calibrated
  std::vector<RadarCalibration> radars;  // in the rig's order; the reference first, as given
  Trajectory reference;                  // the reference radar's odometry, T_world_ref on the body's clock
  bool gyro = false;                     // the reference's angular velocity came from the IMU's gyro
};

// An IMU on the body for the calibration: its samples (its frame, its
// clock), T_body_imu and the window's options (its clock offset: the IMU's
// stamps minus the body's clock).
struct RigImu {
  std::vector<ImuSample> samples;
  SE3d body_from_imu;
  RadarInertialOptions inertial;
};

// `scans[r]`: radar r's scans, stamps on its own clock (as its files hold
// them). Throws DataError for a count of scan lists other than the rig's
// radars, a reference radar without scans or a radar whose scans fall
// outside the reference's drive. With `imu`, the reference's odometry runs
// with the IMU's window, and the reference's angular velocity comes from the
// gyro (less the window's bias) instead of its poses' differences, whose
// rate lags the turn (docs/design/rig.md, "Calibration of a rig").
RigCalibration CalibrateRig(const Rig& rig, const std::vector<std::vector<RadarScan>>& scans,
                            const RigCalibrationOptions& options = {}, const std::optional<RigImu>& imu = std::nullopt);

}  // namespace radargauss
