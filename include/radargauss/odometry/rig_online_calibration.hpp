// SPDX-License-Identifier: BSD-3-Clause
// The online calibration of a rig (docs/design/rig.md, "Online calibration"):
// each radar's extrinsic T_ref_radar and clock offset against the reference
// radar, estimated while the rig drives. The reference's registered poses
// and its own Doppler velocity give its motion, its static points a map of
// the window; every other radar's static points hold the offline
// calibration's residuals on its mounting: their Doppler and their
// positions against that map (residuals/rig_doppler_residual.hpp).
//
// The drive is cut into windows of `calibration_window` s. In each, a
// radar's estimate is solved from the window's Doppler and map, with the
// estimate so far as a prior (a sequential least squares over the windows). The
// calibration gate (solvers/calibration_gate.hpp) then applies only the
// directions that the drive so far observes: the rotation about the
// velocity needs turns, the translation needs turns (the lever arm w x t),
// the clock needs changes of speed. A window whose estimate lies improbably
// far from the rig file, under the prior, is set aside.
//
//   RigOnlineCalibration calibration(reference_from_radar, options.rig);
//   calibration.AddReference(stamp, T_world_ref, velocity);   // each frame
//   calibration.AddScan(radar, scan, static_points);          // each scan
//   if (calibration.Update()) ... calibration.reference_from_radar(r) ...
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "radargauss/core/types.hpp"
#include "radargauss/lie/se3.hpp"
#include "radargauss/odometry/radar_odometry.hpp"

namespace radargauss {

namespace rig_calibration {
struct ReferenceMap;
}

class RigOnlineCalibration {
 public:
  using Vector7d = Eigen::Matrix<double, 7, 1>;
  using Matrix7d = Eigen::Matrix<double, 7, 7>;

  // `reference_from_radar`: the given T_ref_radar of each radar (the first is
  // the reference, never estimated). Throws std::invalid_argument for a bad options.
  RigOnlineCalibration(std::vector<SE3d> reference_from_radar, const RigOdometryOptions& options);

  // The reference radar at a registered frame: T_world_ref and its own Doppler
  // velocity (its frame), `stamp` on the body's clock.
  void AddReference(double stamp, const SE3d& world_from_reference, const Eigen::Vector3d& velocity);
  // A scan of radar `radar`, its stamp on the body's clock by the given
  // offsets, and its static points: the reference's make the map (with the
  // frame registered next at its stamp); of another radar at most 40, spread
  // over the scan, are kept for its window.
  void AddScan(std::size_t radar, const RadarScan& scan, const std::vector<bool>& static_points);
  // Once the reference's frames span the window: each radar's estimate from
  // the window's scans, then the window is left behind. True when an
  // estimate moved.
  bool Update();
  // The reference's poses jumped (a relocalisation's fix): the window restarts.
  void Forget();

  std::size_t radars() const { return estimates_.size(); }
  // Radar r's mounting as applied: T_ref_radar, and the change of its clock
  // offset from the given one (s; its scans' body time is their stamp less
  // this); the given one along the directions not observed yet.
  const SE3d& reference_from_radar(std::size_t r) const { return estimates_[r].applied; }
  double clock_change(std::size_t r) const { return estimates_[r].applied_clock; }
  // The applied estimate's standard deviations: rotation (rad, about the
  // radar's own axes: R Exp(dphi)), translation (m), clock (s); the prior's
  // along the directions not observed.
  Vector7d std(std::size_t r) const;
  // How many directions of its rotation, translation and clock the drive so far observes (3, 3, 1: all).
  const Eigen::Vector3i& observed_directions(std::size_t r) const { return estimates_[r].observed_directions; }
  std::size_t windows() const { return windows_; }
  // Whether the drive so far observes radar r's mounting: its rotation and
  // clock in full, its translation but at most one direction (the
  // reference: always).
  bool Calibrated(std::size_t r) const {
    const Eigen::Vector3i& observed = estimates_[r].observed_directions;
    return r == 0 || (observed(0) == 3 && observed(1) >= 2 && observed(2) == 1);
  }
  // The windows whose estimate of radar r lay improbably far from the rig
  // file (chi-square of 7 degrees of freedom under the prior, beyond 99.9 %): set aside.
  std::size_t windows_set_aside(std::size_t r) const { return estimates_[r].windows_set_aside; }

 private:
  // A radar's estimate: the free one (sequential least squares over the
  // windows, every direction), and the one applied (the given mounting moved
  // to the free one along the observed directions).
  struct Estimate {
    SE3d given, free, applied;
    double free_clock = 0.0, applied_clock = 0.0;  // changes from the given offset
    Matrix7d prior_information = Matrix7d::Zero();
    Matrix7d information = Matrix7d::Zero();  // the prior's and every window's
    Matrix7d covariance = Matrix7d::Zero();   // of the applied estimate
    Eigen::Vector3i observed_directions = Eigen::Vector3i::Zero();
    std::size_t windows_set_aside = 0;
  };
  struct WindowScan {
    std::size_t radar = 0;
    double stamp = 0.0;
    std::vector<Eigen::Vector3d> positions;
    std::vector<double> dopplers;
  };
  bool Solve(std::size_t radar, const std::vector<OdometryStep>& steps, const rig_calibration::ReferenceMap* map);
  bool Apply(Estimate& estimate) const;

  RigOdometryOptions options_;
  std::vector<Estimate> estimates_;
  std::vector<OdometryStep> reference_;  // the window's frames: stamp, pose, velocity
  std::vector<WindowScan> scans_;
  std::optional<RadarScan> reference_scan_;  // the reference's static points, until its frame is registered
  std::vector<RadarScan> map_scans_;         // the reference's, for the window's map
  std::vector<SE3d> map_poses_;
  std::size_t windows_ = 0;
};

}  // namespace radargauss
