// SPDX-License-Identifier: BSD-3-Clause
// Radar odometry on a Gaussian-RCS map it builds itself (docs/design/odometry.md,
// "Odometry"). Per scan, in time order: the Doppler ego velocity gated by
// the motion model's prediction; a predicted pose (translation from that
// velocity, rotation from gyro rates or at the last yaw rate, roll and pitch
// held);
// scan-to-map matching of the static points with eq. 2 plus the Doppler
// velocity and rotation terms; the static points into the local map on keyframes.
//
//   RadarOdometry odometry(options);
//   for (const RadarScan& scan : sequence.scans) odometry.Register(scan);
//   WriteTum(path, odometry.trajectory());
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "radargauss/core/doppler.hpp"
#include "radargauss/lie/se3.hpp"
#include "radargauss/odometry/elevation_bias.hpp"
#include "radargauss/odometry/local_map.hpp"
#include "radargauss/odometry/motion_model.hpp"
#include "radargauss/solvers/factory.hpp"
#include "radargauss/core/trajectory.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

// Odometry's Doppler RANSAC-LSQ: support counted in 1 m voxels, so that the
// car ahead does not pass for the world before any prediction can gate it.
inline EgoVelocityOptions OdometryEgoVelocityOptions() {
  EgoVelocityOptions options;
  options.consensus_voxel = 1.0;
  return options;
}

// How a rig's scans become the odometry's frames (odometry/rig_odometry.hpp,
// docs/design/rig.md, "Odometry on a rig"); unused with one radar.
struct RigOdometryOptions {
  // s: the longest a frame's scans may span on the body's clock; a frame
  // closes early when the reference radar drops a scan.
  double max_frame_span = 0.1;
  // The frame's velocity from every radar's Doppler (the rig's twist at the
  // reference radar); false: from the reference radar's alone.
  bool rig_velocity = true;
  // The rig's rotation rates (its twist, where it observes all three) as the
  // rotation term's prediction, with the twist's covariance: "yaw" about the
  // vertical; "all" roll and pitch too (they come from the points'
  // elevations, which a radar's elevation bias tilts); "off".
  std::string rotation_rate = "yaw";
  // Each scan's points moved from its stamp to the frame's at the frame's velocity and the last rotation rate.
  bool motion_compensation = true;
  // Each radar's extrinsic and clock offset estimated while driving, in
  // windows of calibration_window s, where the window's Doppler observes
  // them (odometry/rig_online_calibration.hpp); the frames that follow use them.
  bool calibrate = false;
  double calibration_window = 2.5;        // s of the reference's frames per estimate
  double calibration_doppler_std = 0.05;  // m/s: a Doppler residual's sigma
  double calibration_map_weight = 1.0;    // of the points against the reference's map (0: the Doppler alone)
  // How far the rig file's mountings may be off (the first prior's stds of
  // the rotation, the translation and the clock: deg, m, s) ...
  Eigen::Vector3d calibration_prior{2.0, 0.1, 0.02};
  // ... and the std the drive's data must reach in a direction to move it there (deg, m, s).
  Eigen::Vector3d calibration_observed{0.2, 0.03, 0.002};
};
const OptionTable<RigOdometryOptions>& RigOdometryOptionTable();

struct OdometryOptions {
  EgoVelocityOptions ego_velocity = OdometryEgoVelocityOptions();
  // The gate on Doppler hypotheses around the predicted velocity:
  // gate_sigmas * sqrt(lambda_max(S) + (acceleration_std * dt)^2), at least
  // min_gate; dt counts from the last scan whose velocity was measured.
  double gate_sigmas = 3.0;
  double acceleration_std = 3.0;       // m/s^2: process noise of the velocity
  double min_gate = 0.5;               // m/s
  std::size_t min_static_points = 10;  // fewer Doppler inliers: the prediction stands in
  double velocity_weight = 1.0;        // of the velocity term in eq. 2 (0: off)
  double velocity_floor = 0.05;        // m: std of the floor Q = diag(floor^2, floor^2, vertical^2) of the term
  // m: the floor along the radar's z. Larger lets the term leave the vertical
  // to the geometry (an elevation bias tilts the Doppler velocity, not the
  // scan's fit to the map: docs/design/simulator.md, "The faults of real radars"); 0: velocity_floor.
  double velocity_vertical_floor = 0.0;
  // The rotation term: the match's rotation against the predicted one, with
  // sigma = rotation_rate_std * dt about the radar's x, y, z (roll, pitch,
  // yaw); docs/design/residuals.md, "The rotation term".
  double rotation_weight = 1.0;                           // 0: off
  Eigen::Vector3d rotation_rate_std_deg{1.0, 1.0, 90.0};  // deg/s: rate changes the prediction allows
  MatchOptions match;                                     // solver and eq. 2 (w_rcs, losses, incidence via map.rcs)
  LocalMapOptions map;
  double keyframe_distance = 0.5;   // m since the last keyframe ...
  double keyframe_angle_deg = 2.0;  // ... or deg: the scan enters the map
  // A keyframe's map update runs on a thread of its own behind the scan's
  // step, finished before the next scan's match reads the map, when more
  // than one thread is allowed (docs/design/odometry.md, "The map update
  // behind the step"): the same map and trajectory either way.
  bool background_map_update = true;
  std::size_t min_matched_points = 10;  // fewer associated points: the prediction stands in
  SE3d initial_pose;                    // T_world_radar of the first scan
  // The radar on the vehicle, roll / pitch / yaw in deg (VehicleFromRadar;
  // `radargauss odometry` prints an estimate): the prediction turns about
  // the vehicle's vertical and the rotation term's stds are about its axes.
  Eigen::Vector3d mounting_deg = Eigen::Vector3d::Zero();
  // The elevation bias estimated from the Doppler velocity and removed
  // (odometry/elevation_bias.hpp), beyond what the sequence's reading removed.
  ElevationBiasOptions elevation_bias;
  RigOdometryOptions rig;
};

// R_vehicle_radar = Rz(yaw) Ry(pitch) Rx(roll) (z up, a positive pitch looks
// down: docs/design/odometry.md, "Mounting").
SO3d VehicleFromRadar(const Eigen::Vector3d& roll_pitch_yaw_deg);

// Its options (options.hpp): its own, then the Doppler filter's, the
// match's, the local map's and the elevation bias's; ValidateOptions throws
// std::invalid_argument naming the bad one.
const OptionTable<OdometryOptions>& OdometryOptionTable();
void ValidateOptions(const OdometryOptions& options);

// What happened to one scan.
struct OdometryStep {
  double stamp = 0.0;
  SE3d pose;  // T_world_radar
  std::size_t points = 0;
  std::size_t static_points = 0;                                  // Doppler inliers (all points without Doppler)
  bool velocity_measured = false;                                 // false: the prediction's velocity
  bool standstill = false;                                        // the zero-velocity branch held the pose
  bool gyro = false;                                              // the predicted rotation comes from gyro rates
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();             // m/s, radar frame
  Eigen::Matrix3d velocity_covariance = Eigen::Matrix3d::Zero();  // (m/s)^2: measured, or the prediction's
  bool matched = false;                                           // the pose comes from scan matching
  int iterations = 0;
  double final_cost = 0.0;
  bool converged = false;
  std::string reason;  // why a stage fell back or did not converge; empty when all went well
  bool keyframe = false;
  std::size_t active_gaussians = 0;  // after the map update
  std::size_t active_map_bytes = 0;  // LocalMap::MemoryBytes after the map update
  // The step until its pose was known and, on the scan's path, its map
  // update; with the update behind the step, the wait for the last one.
  double time_ms = 0.0;
  double map_update_ms = 0.0;  // a keyframe's map update (LocalMap::Insert and Evict), wherever it ran
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();           // eq. 2's
  Eigen::Matrix<double, 6, 6> velocity_information = Eigen::Matrix<double, 6, 6>::Zero();  // the term's
  Eigen::Matrix<double, 6, 6> rotation_information = Eigen::Matrix<double, 6, 6>::Zero();  // the rotation term's
};

// The scan matcher of a version of the active map: by default
// MakeScanMatcher(options.match). RadarOdometry calls it once per
// LocalMap::version() (the map changes on keyframes) and hands each scan its
// velocity and rotation priors as arguments of Match. Another factory puts
// other matchers (the PCL peers) in the same loop, map policy and Doppler filter.
using MatcherFactory =
    std::function<std::shared_ptr<const ScanMatcher>(const LocalMap& map, const MatchOptions& options)>;
// The default: MakeScanMatcher(options), the Gaussian solvers.
MatcherFactory GaussianMatcherFactory();

class RadarOdometry {
 public:
  // `motion`: the motion model (odometry/motion_model.hpp; null: constant
  // velocity); `matcher`: the matcher factory (null: GaussianMatcherFactory).
  explicit RadarOdometry(const OdometryOptions& options = {}, std::unique_ptr<MotionModel> motion = nullptr,
                         MatcherFactory matcher = nullptr);

  // Registers the next scan. Throws DataError when its stamp is not after the
  // previous one's or is not finite; every other fault becomes a reason.
  // With the map update behind the step (map_update_behind()), a keyframe's
  // map fields (active_gaussians, active_map_bytes, map_update_ms) are
  // completed when it finishes: steps(), map() or FinishMapUpdate().
  const OdometryStep& Register(const RadarScan& scan);
  // The same for a scan without Doppler whose sensor velocity (m/s, the
  // scan's frame) was measured apart, with its covariance: a rig's body
  // velocity from its radars' Doppler (odometry/rig_odometry.hpp). Every
  // point is matched, as without Doppler.
  // The rotation rate measured with it (rad/s, the scan's frame) and its
  // covariance: with the last scan's, the rotation term's prediction (its
  // yaw about the vehicle's vertical; with `all`, roll and pitch too),
  // unless the motion model's gyro gives the rotation.
  struct MeasuredRate {
    Eigen::Vector3d value = Eigen::Vector3d::Zero();
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    bool all = false;
  };
  struct MeasuredVelocity {
    Eigen::Vector3d value = Eigen::Vector3d::Zero();
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    std::optional<MeasuredRate> rate;
  };
  const OdometryStep& Register(const RadarScan& scan, const std::optional<MeasuredVelocity>& velocity);
  // From the next scan on, matches against `map`, fixed (nothing is
  // inserted), with the motion model carried into the map's frame by
  // `map_from_odometry`: localisation in a given map (relocalisation's tracking).
  void LocalizeIn(std::shared_ptr<const MatchingMap> map, const SE3d& map_from_odometry);

  // The steps and the map finish a map update still behind the last step first.
  const std::vector<OdometryStep>& steps() const {
    FinishMapUpdate();
    return steps_;
  }
  // Without waiting for the map: the number of steps, and step k's pose.
  std::size_t scans() const { return steps_.size(); }
  const SE3d& pose(std::size_t k) const { return steps_.at(k).pose; }
  Trajectory trajectory() const;
  const LocalMap& map() const {
    FinishMapUpdate();
    return map_;
  }
  // Waits for the map update behind the last step (rethrowing what it threw)
  // and completes that step's map fields.
  void FinishMapUpdate() const;
  // Whether keyframes' map updates run behind the steps (background_map_update and more than one thread).
  bool map_update_behind() const { return map_update_ != nullptr; }
  // The indices of the last registered scan's static points (Doppler inliers;
  // every point of a scan without Doppler; none when the prediction stood in).
  const std::vector<std::size_t>& last_static_points() const { return last_static_points_; }
  const OdometryOptions& options() const { return options_; }
  const MotionModel& motion() const { return *motion_; }
  // The elevation bias removed from the points now (deg): the estimate.
  double elevation_bias_deg() const { return elevation_bias_.bias_deg(); }
  // How many matchers the factory has made: one per map version matched against.
  std::size_t matchers_made() const { return matchers_made_; }

 private:
  // What the motion model keeps of the past: the last two poses (the yaw
  // rate), the last velocity with its covariance, the last measured one's
  // stamp and covariance (the gate's centre of trust).
  struct MotionState {
    double stamp = 0.0;
    SE3d pose;
    std::optional<std::pair<double, SE3d>> before;  // the scan before: stamp, pose
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    Eigen::Matrix3d velocity_covariance = Eigen::Matrix3d::Zero();
    std::optional<std::pair<double, Eigen::Matrix3d>> measured;  // stamp, velocity covariance
    std::optional<MeasuredRate> rate;                            // measured apart with the velocity
  };
  // The motion model's guess for the next scan.
  struct Prediction {
    SO3d increment;            // rotation since the last scan (gyro, or the last yaw rate)
    Eigen::Vector3d velocity;  // the last velocity, kept in the radar frame
    Eigen::Matrix3d velocity_covariance;
    double dt = 0.0;
    bool gyro = false;  // the increment comes from the motion model
    // The increment's std (rad) when measured rates gave it: about the
    // vehicle's vertical, or about the radar's axes with every rate.
    std::optional<double> yaw_std;
    std::optional<Eigen::Vector3d> increment_std;
  };
  // The scan's ego velocity: measured (gated by the prediction), or the prediction's.
  struct Velocity {
    bool measured = false;
    bool standstill = false;  // the zero-velocity branch decided
    Eigen::Vector3d value = Eigen::Vector3d::Zero();
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    std::vector<std::size_t> static_points;  // to match and to insert
    std::string reason;                      // why the prediction stands in
  };
  // The scan's pose: matched, or the prediction's (with why).
  struct PoseEstimate {
    SE3d pose;
    std::optional<ScanMatchingResult> match;  // when a match was made
    bool matched = false;                     // the pose is the match's
    std::string reason;
  };

  void CheckStamp(const RadarScan& scan) const;
  // The radar alone beside a model on probation; true when the model failed
  // on this scan and the radar alone's run has become this one.
  bool RunBeside(const RadarScan& scan, const std::optional<MeasuredVelocity>& measured);
  Prediction Predict(double stamp) const;
  // The increment (and its std) from the rates measured at the last scan and this one.
  void PredictFromRates(const MeasuredRate& before, const MeasuredRate& now, Prediction& p) const;
  SE3d PredictedPose(const Prediction& prediction, const Eigen::Vector3d& velocity) const;
  // The translation since the last scan in its frame for a velocity of the new frame.
  static Eigen::Vector3d Displacement(const Prediction& prediction, const Eigen::Vector3d& velocity);
  Velocity MeasureVelocity(const RadarScan& scan, const std::optional<Prediction>& prediction,
                           const std::optional<MeasuredVelocity>& measured) const;
  PoseEstimate EstimatePose(const RadarScan& scan, const std::optional<Prediction>& prediction,
                            const Velocity& velocity);
  PoseEstimate Match(const RadarScan& scan, const Prediction& prediction, const Velocity& velocity,
                     const SE3d& predicted);
  // The velocity and rotation terms of a scan matched from the prediction.
  ScanPriors PriorsOf(const Prediction& prediction, const Velocity& velocity) const;
  const ScanMatcher& MatcherForMap();
  // Whether the scan at `pose` enters the map (the first, or far or turned enough since the last keyframe).
  bool IsKeyframe(const SE3d& pose, const Velocity& velocity) const;
  // Runs the keyframe's map update, or posts it behind the step `step`.
  void InsertKeyframe(const RadarScan& scan, const std::vector<std::size_t>& static_points, const SE3d& pose,
                      std::size_t step);
  // Records the map after an update in step `step`: its Gaussians, bytes
  // (measured now when `measure`, else the update's) and the update's time.
  void RecordMap(std::size_t step, bool measure) const;
  static ScanEstimate EstimateOf(const RadarScan& scan, const Velocity& velocity, const PoseEstimate& estimate);
  OdometryStep StepOf(const RadarScan& scan, const std::optional<Prediction>& prediction, const Velocity& velocity,
                      const PoseEstimate& estimate, bool keyframe) const;

  OdometryOptions options_;
  SO3d vehicle_from_radar_;  // of options_.mounting_deg
  ElevationBias elevation_bias_;
  std::unique_ptr<MotionModel> motion_;
  MatcherFactory factory_;
  std::shared_ptr<const ScanMatcher> matcher_;  // for map_ at matcher_version_
  std::size_t matcher_version_ = 0;
  std::size_t matchers_made_ = 0;
  LocalMap map_;
  // The record of the run (the motion model reads state_); a step's map
  // fields are completed when a map update behind it finishes.
  mutable std::vector<OdometryStep> steps_;
  std::optional<MotionState> state_;
  SE3d last_keyframe_;
  std::vector<std::size_t> last_static_points_;
  std::shared_ptr<const MatchingMap> fixed_map_;  // LocalizeIn's; null: the run's own map
  mutable std::size_t map_bytes_ = 0;             // LocalMap::MemoryBytes after the last keyframe
  // The radar alone, run beside while the motion model is on probation.
  std::unique_ptr<RadarOdometry> radar_alone_;
  // The step whose map update is behind it, and the update's time (ms, the worker's).
  mutable std::optional<std::size_t> pending_step_;
  double pending_update_ms_ = 0.0;
  // The map update's task (a tbb::task_group, kept out of this header); it
  // is waited for before it goes (last: before the map it updates).
  struct MapUpdateTask;
  struct WaitAndDelete {
    void operator()(MapUpdateTask* task) const;
  };
  static std::unique_ptr<MapUpdateTask, WaitAndDelete> NewMapUpdateTask();
  mutable std::unique_ptr<MapUpdateTask, WaitAndDelete> map_update_;
};

// Per-scan time (median, p90 in ms), scan and keyframe counts, fallbacks.
struct OdometrySummary {
  std::size_t scans = 0, keyframes = 0, matched = 0, velocity_predicted = 0, standstill = 0, pose_predicted = 0;
  double median_ms = 0.0, p90_ms = 0.0, path_length = 0.0;  // path: m, of the estimate
  std::size_t active_gaussians = 0, global_gaussians = 0, map_bytes = 0;
};
OdometrySummary Summarise(const RadarOdometry& odometry);

// Writes odometry.tum (T_world_radar), levelled.tum (when the mounting is
// observable, odometry/mounting.hpp), per_scan.csv, summary.json, map.rgm
// and map.ply (when the map keeps its evicted Gaussians) into `dir`
// (created), each file whole or not at all. With an
// inertial window as the motion model also inertial.csv (the window's newest
// state per scan) and summary.json's `calibration` (the tilt, the biases, the
// extrinsic when estimated, each with its standard deviation).
void WriteOdometry(const std::string& dir, const RadarOdometry& odometry);

}  // namespace radargauss
