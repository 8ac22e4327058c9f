// SPDX-License-Identifier: BSD-3-Clause
// Odometry of a rig of radars (docs/design/rig.md, "Odometry on a rig"): one
// trajectory of the body, T_world_body, from every radar's scans matched
// into one map. The odometry runs in the first radar's frame (the
// reference) and registers frames:
//
// - a frame closes at each scan of the reference radar (with the scans of
//   its instant), or when its scans would span more than max_frame_span;
// - the frame's velocity and static points come from every radar's Doppler
//   at once (the rig's twist, core/rig_twist.hpp, at the reference radar);
// - each scan's static points are moved through its mounting into the
//   reference frame and, by that twist, from their own stamp to the frame's.
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
#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "radargauss/core/trajectory.hpp"
#include "radargauss/io/rig.hpp"
#include "radargauss/lie/se3.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/odometry/rig_online_calibration.hpp"

namespace radargauss {

// One frame of a rig: every radar's static points in the reference radar's
// frame at the frame's stamp (without Doppler), and its velocity when measured.
struct RigFrame {
  RadarScan scan;
  std::optional<RadarOdometry::MeasuredVelocity> velocity;
  bool velocity_by_rig = false;     // the rig's twist measured it (else the reference radar)
  std::vector<std::size_t> radars;  // the radar of each scan in the frame
  double build_ms = 0.0;            // its twist and its points moved
};

// A rig's scans made into frames, for any front end that registers them
// (RigOdometry, RadarSlam): give each scan in the body's time order, register
// each frame returned, and tell the frames where it was registered.
class RigFrames {
 public:
  // Throws DataError for no radar, std::invalid_argument for a bad options.rig
  // or an elevation bias to estimate over several radars.
  RigFrames(std::vector<SE3d> body_from_radar, const OdometryOptions& options);

  // `scan` of radar `radar`, its timestamp on the body's clock (not before
  // the last scan's); the frame it closed, if any. Throws DataError for an
  // unknown radar, a stamp that goes back or a scan ValidateScan refuses.
  std::optional<RigFrame> Add(std::size_t radar, const RadarScan& scan);
  // The last frame, if scans are left.
  std::optional<RigFrame> Finish();
  // The pose T_world_ref a frame was registered at: the rotation rate that
  // moves the next frames' scans comes from the last two.
  void Registered(double stamp, const SE3d& pose);
  // The front end's poses jumped (a relocalisation's fix, a restart): the
  // rotation rate waits for two frames registered after it, the online
  // calibration for a new window.
  void ForgetMotion();

  std::size_t radars() const { return body_from_radar_.size(); }
  const SE3d& body_from_reference() const { return body_from_radar_.front(); }
  // Each radar's T_ref_radar as the frames use it: the rig file's, or the
  // online calibration's estimate (options.rig.calibrate).
  const std::vector<SE3d>& reference_from_radar() const { return reference_from_radar_; }
  // The online calibration, when options.rig.calibrate on a rig of several radars.
  const RigOnlineCalibration* online_calibration() const {
    return online_calibration_ ? &*online_calibration_ : nullptr;
  }

 private:
  // A frame's velocity: measured (by the rig's twist or the reference
  // radar), each scan's static points, and the twist [v; w] that moves the
  // scans to the frame's stamp (w: the last rotation rate).
  struct FrameVelocity {
    std::optional<RadarOdometry::MeasuredVelocity> measured;
    bool by_rig = false;
    std::vector<std::vector<bool>> static_points;
    Eigen::Matrix<double, 6, 1> twist = Eigen::Matrix<double, 6, 1>::Zero();
    std::optional<Eigen::Vector3d> reference;  // the reference radar's own velocity
  };
  // The odometry's Doppler gate (OdometryOptions).
  struct GateOptions {
    explicit GateOptions(const OdometryOptions& o)
        : gate_sigmas(o.gate_sigmas), acceleration_std(o.acceleration_std), min_gate(o.min_gate) {}
    double gate_sigmas, acceleration_std, min_gate;
  };
  RigFrame Close();
  std::optional<VelocityGate> Gate(double stamp) const;
  FrameVelocity MeasureVelocity(const std::optional<VelocityGate>& gate) const;
  // Scan k's static points by its radar's own Doppler filter.
  std::vector<bool> OwnStaticPoints(std::size_t k, const std::optional<VelocityGate>& gate,
                                    const FrameVelocity& frame) const;
  // Whether radar `radar`'s scans join the rig's twist and the frame's
  // points: always, but with the online calibration, once it has observed
  // the radar's mounting (until then the frames are the others').
  bool Admitted(std::size_t radar) const { return !online_calibration_ || online_calibration_->Calibrated(radar); }
  // The reference radar's twist [v; w] (its frame) between the last two frames registered; zero before.
  Eigen::Matrix<double, 6, 1> LastTwist() const;

  std::vector<SE3d> body_from_radar_;
  std::vector<SE3d> reference_from_radar_;
  EgoVelocityOptions doppler_;
  GateOptions gate_;
  RigOdometryOptions rig_options_;  // options.rig
  std::vector<RadarScan> pending_;  // the frame's scans, not yet closed
  std::vector<std::size_t> pending_radars_;
  std::optional<double> closing_stamp_;              // the reference radar's scan in the frame
  std::optional<double> last_stamp_;                 // of the last scan added
  std::vector<std::pair<double, SE3d>> registered_;  // the last two frames' stamps and poses
  struct MeasuredAt {
    double stamp = 0.0;
    RadarOdometry::MeasuredVelocity velocity;
  };
  std::optional<MeasuredAt> last_measured_;  // the gate's centre
  std::optional<RigOnlineCalibration> online_calibration_;
  // The last frame's stamp and its reference radar's own velocity, for the
  // online calibration once the frame is registered.
  std::optional<std::pair<double, Eigen::Vector3d>> reference_velocity_;
};

// What a front end tells of a frame it registered: the pose T_world_ref it
// gave it, and whether its poses jumped before it (a relocalisation's fix,
// a restart).
struct RegisteredFrame {
  SE3d pose;
  bool jumped = false;
};
// Every scan of `rig` (ForEachRigScan) made into frames that `front_end`
// registers (RadarSlam, Relocalizer): a rig of one radar gives each scan
// as it is, as its own frame without a velocity. Returns the scans read;
// throws DataError as ForEachRigScan and RigFrames do, naming the scan's source.
// `calibrated`, when given: the rig as the online calibration left it
// (OnlineCalibratedRig; `rig` itself without options.rig.calibrate).
std::size_t RegisterRigFrames(const Rig& rig, const OdometryOptions& options,
                              const std::function<RegisteredFrame(const RigFrame&)>& front_end,
                              Rig* calibrated = nullptr);

// The odometry's options for a rig's reference radar: its mounting (the
// vehicle's vertical for the rotation term and the yaw rate's axis) is the
// roll and pitch of T_body_ref (its yaw leaves the vertical as it is). Throws
// std::invalid_argument for a `mounting` given apart: a rig's mountings are
// in its file.
OdometryOptions ReferenceRadarOptions(OdometryOptions options, const SE3d& body_from_reference);

// `given` with the online calibration's mountings (T_body_radar = T_body_ref
// T_ref_radar) and clock offsets (the given plus the estimated change); as
// given without it.
Rig OnlineCalibratedRig(const Rig& given, const RigFrames& frames);

// The motion model of a rig's IMU (MakeMotionModel) for the reference radar's
// odometry: in its frame, T_ref_imu = T_body_ref^-1 T_body_imu
// (docs/design/rig.md, "An IMU on a rig"); constant velocity without samples.
std::unique_ptr<MotionModel> MakeRigMotionModel(const RadarInertialOptions& options, const SE3d& body_from_reference,
                                                const SE3d& body_from_imu, std::vector<ImuSample> imu);

// The body's trajectory from the reference radar's, T_world_ref in its
// first frame: T_world_body = M T M^-1 (M = T_body_ref), so that the body
// starts where the reference does.
Trajectory BodyTrajectory(const Trajectory& reference, const SE3d& body_from_reference);

class RigOdometry {
 public:
  // `body_from_radar`: T_body_radar of each radar. The odometry's Doppler
  // filter (options.ego_velocity) serves every radar; the map and the match
  // are the body's; options.rig says how scans become frames (RigFrames).
  // The reference radar's odometry takes ReferenceRadarOptions.
  // `motion`: the motion model of the reference radar's odometry (null:
  // constant velocity); an IMU's (MakeMotionModel) takes T_ref_imu =
  // T_body_ref^-1 T_body_imu and stamps on the body's clock (one window
  // over the rig: docs/design/rig.md, "An IMU on a rig").
  // Throws DataError for no radar, std::invalid_argument for a bad option.
  RigOdometry(std::vector<SE3d> body_from_radar, const OdometryOptions& options = {},
              std::unique_ptr<MotionModel> motion = nullptr);

  // `scan` of radar `radar`, its timestamp on the body's clock (not before
  // the last scan's). Throws DataError for an unknown radar or a stamp that
  // goes back.
  void Register(std::size_t radar, const RadarScan& scan);
  // Registers the last frame.
  void Finish();

  // T_world_body at each frame.
  Trajectory trajectory() const;
  // The odometry the frames went through, in the first radar's frame
  // (with one radar, that radar's own).
  const RadarOdometry& odometry() const { return odometry_; }
  // Each frame's radars (one entry per scan), the frames whose velocity the
  // Doppler measured, and those measured by the rig's twist.
  const std::vector<std::vector<std::size_t>>& frame_radars() const { return frame_radars_; }
  std::size_t velocity_measured() const { return velocity_measured_; }
  std::size_t rig_velocity_measured() const { return rig_velocity_measured_; }
  // The last frame registered: every radar's static points in the reference
  // radar's frame at the frame's stamp, without Doppler (empty with one radar).
  const RadarScan& last_frame() const { return last_frame_; }
  // Each frame's time (ms): its twist, its points moved and its odometry step (empty with one radar).
  const std::vector<double>& frame_times_ms() const { return frame_times_ms_; }
  // The frames' maker: each radar's mounting as used, the online calibration.
  const RigFrames& frames() const { return frames_; }

 private:
  void RegisterFrame(RigFrame frame);

  RigFrames frames_;
  RadarOdometry odometry_;
  std::vector<std::vector<std::size_t>> frame_radars_;
  RadarScan last_frame_;
  std::vector<double> frame_times_ms_;
  std::size_t velocity_measured_ = 0;
  std::size_t rig_velocity_measured_ = 0;
};

}  // namespace radargauss
