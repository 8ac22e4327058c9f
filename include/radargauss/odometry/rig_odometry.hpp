// SPDX-License-Identifier: BSD-3-Clause
// Odometry of a rig of radars (docs/design/rig.md, "Odometry on a rig"): one
// trajectory of the body, T_world_body, from every radar's scans matched
// into one map. The scans of one instant on the body's clock (ties) are
// registered together, the scans of other instants each on their own, so
// no radar waits for another:
//
// - the odometry runs in the first radar's frame (the reference radar);
// - every radar's static points (its own Doppler filter) are moved into it
//   through the mountings and matched as one scan;
// - the reference radar's Doppler velocity, at the instants it scans, is the
//   measured velocity; at the others the motion model predicts it.
//
// A rig of one radar is the single-radar odometry, bit for bit, its poses
// moved to the body through the mounting.
//
//   RigOdometry odometry(mountings, options);
//   ForEachRigScan(rig, [&](std::size_t radar, RadarScan& scan, const std::string&) {
//     odometry.Register(radar, scan);
//   });
//   odometry.Finish();
//   WriteTum(path, odometry.trajectory());
#pragma once

#include <cstddef>
#include <vector>

#include "radargauss/core/trajectory.hpp"
#include "radargauss/lie/se3.hpp"
#include "radargauss/odometry/radar_odometry.hpp"

namespace radargauss {

class RigOdometry {
 public:
  // `body_from_radar`: T_body_radar of each radar. The odometry's Doppler
  // filter (options.ego_velocity) serves every radar; the map and the match
  // are the body's.
  RigOdometry(std::vector<SE3d> body_from_radar, const OdometryOptions& options = {});

  // `scan` of radar `radar`, its timestamp on the body's clock (not before
  // the last scan's). Throws DataError for an unknown radar or a stamp that
  // goes back.
  void Register(std::size_t radar, const RadarScan& scan);
  // Registers the scans of the last instant.
  void Finish();

  // T_world_body at each registered instant.
  Trajectory trajectory() const;
  // The odometry the instants went through, in the first radar's frame
  // (with one radar, that radar's own).
  const RadarOdometry& odometry() const { return odometry_; }
  // Each instant's radars, and the instants whose velocity the Doppler measured.
  const std::vector<std::vector<std::size_t>>& instant_radars() const { return instant_radars_; }
  std::size_t velocity_measured() const { return velocity_measured_; }

 private:
  void RegisterPending();

  std::vector<SE3d> body_from_radar_;
  EgoVelocityOptions doppler_;
  RadarOdometry odometry_;
  std::vector<RadarScan> pending_;  // the instant's scans, not yet registered
  std::vector<std::size_t> pending_radars_;
  std::vector<std::vector<std::size_t>> instant_radars_;
  std::size_t velocity_measured_ = 0;
};

}  // namespace radargauss
