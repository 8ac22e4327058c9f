// SPDX-License-Identifier: BSD-3-Clause
// A sliding window of IMU states at the radar's scans (docs/design/solvers.md, "The
// sliding window"): pose, velocity and biases in a gravity-aligned world,
// tied by preintegrated IMU terms (residuals/imu_residual.hpp) and held by
// the radar's terms (residuals/radar_inertial_residuals.hpp): the scan
// match's pose and information, and the Doppler ego velocity. A state that
// leaves the window is marginalised into a prior (solvers/marginalization.hpp)
// or dropped. Solved by Ceres's Levenberg-Marquardt or dogleg, or by the own
// Gauss-Newton on the same terms. The radar-IMU extrinsic and the tilt of the
// matcher's world against gravity are blocks too, fixed or estimated.
//
//   InertialWindow window(options, radar_from_imu);
//   window.AddImu(samples);
//   window.Start(first_state);             // at the first scan
//   window.AddPose(match_pose, information); window.AddVelocity(v, S);
//   window.Solve();
//   window.AddState(next_scan_stamp); ...  // then its measurements, Solve
#pragma once

#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/io/imu.hpp"
#include "radargauss/lie/se3.hpp"
#include "radargauss/core/options.hpp"

namespace radargauss {

enum class WindowSolver { kCeresLm, kCeresDogleg, kGaussNewton };
std::string ToString(WindowSolver solver);                     // "ceres-lm", "ceres-dogleg", "gn"
WindowSolver WindowSolverFromString(const std::string& name);  // throws std::invalid_argument
std::vector<std::string> WindowSolverNames();

struct InertialWindowOptions {
  std::size_t size = 5;  // states kept
  WindowSolver solver = WindowSolver::kCeresLm;
  int max_iterations = 5;   // per Solve
  bool marginalize = true;  // false: a leaving state is dropped with all it knew
  ImuNoise noise;
  // The first state's prior (std): its biases about zero, its velocity about the start's.
  double gyro_bias_prior = 0.01;  // rad/s
  double accel_bias_prior = 0.2;  // m/s^2
  double velocity_prior = 1.0;    // m/s
  // The first state's prior on an estimated calibration (std) about its
  // start: an extrinsic file's stated accuracy sets them (ReadStatedExtrinsicFile).
  double extrinsic_rotation_prior_deg = 3.0;  // a mounting is known to a few degrees
  double extrinsic_translation_prior = 0.0;   // m; 0: none
  double clock_offset_prior = 0.05;           // s: held near its start until the drive turns
  bool estimate_tilt = true;                  // the matcher's world's roll and pitch against gravity
  bool estimate_extrinsic_rotation = false;
  bool estimate_extrinsic_translation = false;
  // s: the IMU's stamps minus the radar's clock (the start when estimated).
  double clock_offset = 0.0;
  bool estimate_clock_offset = false;
  // The radar's elevation bias b in the Doppler velocity's term. Not in the
  // table: radar-inertial odometry sets it from OdometryOptions'
  // estimate_elevation_bias, one flag for both front ends.
  bool estimate_elevation_bias = false;
  // m/s: std of the IMU's lateral and vertical velocity in its own frame, a
  // ground vehicle's with the IMU aligned to it (VehicleMotionResidual); 0: no such term.
  double vehicle_motion_std = 0.0;
  // Calibration only where the motion shows it (docs/design/solvers.md, "The
  // calibration gate"): at each solve an estimated calibration block is
  // held along the directions its data do not pin to within these stds.
  // Off by default: on the simulated worlds it held the elevation bias and
  // the clock where the free estimate found them (odometry's figures).
  bool calibration_gate = false;
  double observed_rotation_std_deg = 0.3;
  double observed_translation_std = 0.05;  // m
  double observed_clock_std = 0.003;       // s
  double observed_elevation_bias_std_deg = 0.1;
};

// Its options (options.hpp), named window_*, imu_* (the noise) and estimate_*.
const OptionTable<InertialWindowOptions>& InertialWindowOptionTable();

// An IMU state: T_world_imu in the gravity-aligned world, the velocity there, the biases.
struct InertialState {
  double stamp = 0.0;
  SE3d pose;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s
  ImuBias bias;
};

// Standard deviations of the newest state's biases and velocity and of the
// estimated globals, from the inverse of the window's Gauss-Newton matrix
// at the current estimate (its prior included); zero for what is held fixed.
struct WindowUncertainty {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();               // m/s
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();              // rad/s
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();             // m/s^2
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();                   // rad
  Eigen::Vector3d extrinsic_rotation = Eigen::Vector3d::Zero();     // rad, on the right of R_imu_radar
  Eigen::Vector3d extrinsic_translation = Eigen::Vector3d::Zero();  // m
  double clock_offset = 0.0;                                        // s
  double elevation_bias = 0.0;                                      // rad
};

// The estimated calibration at a solve: its value after it, its std before
// it (the window's marginal, prior included) and how many of its
// directions the data observed (the rest held; -1: not estimated).
struct CalibrationObservation {
  int extrinsic_rotation = -1, extrinsic_translation = -1, clock_offset = -1, elevation_bias = -1;
  Eigen::Vector3d extrinsic_rotation_std = Eigen::Vector3d::Zero();     // rad, on the right of R_imu_radar
  Eigen::Vector3d extrinsic_translation_std = Eigen::Vector3d::Zero();  // m
  double clock_offset_std = 0.0, elevation_bias_std = 0.0;              // s, rad
  SE3d radar_from_imu;
  double clock_offset_value = 0.0, elevation_bias_value = 0.0;  // s, rad
};

struct WindowSolveSummary {
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  bool converged = false;
  std::size_t reintegrated = 0;  // IMU terms integrated again at a moved bias
  // The clock offset's estimate left its bounds (kMaxClockOffset, or the
  // IMU's data beyond the window's ends) and was held at the bound.
  bool clock_offset_held = false;
  CalibrationObservation calibration;
  double time_ms = 0.0;
};

// An estimated clock offset stays within this of zero (the range of
// imu_clock_offset): beyond it the clocks disagree, which no window calibrates.
constexpr double kMaxClockOffset = 0.1;  // s

class InertialWindow {
 public:
  // T_radar_imu: the IMU's frame in the radar's (the extrinsic's start when estimated).
  InertialWindow(const InertialWindowOptions& options, const SE3d& radar_from_imu);
  ~InertialWindow();
  InertialWindow(const InertialWindow&) = delete;
  InertialWindow& operator=(const InertialWindow&) = delete;

  // Appends samples (time order, after those given before; throws DataError otherwise).
  void AddImu(const std::vector<ImuSample>& samples);
  // The first state, with the first-state prior on its biases and velocity.
  void Start(const InertialState& state);
  // A new state at `stamp` (after the last), predicted by the IMU from the
  // last. Throws DataError when the IMU does not cover the interval.
  void AddState(double stamp);
  // Measurements of the newest state: the matcher's T_world_radar with eq. 2's
  // information (translation first), and the Doppler velocity of the radar in
  // its frame with its covariance, fitted to a scan whose elevations were
  // lowered by `elevation_bias_removed` (rad). The IMU's reading at the scan
  // comes from the samples (the one in force at the stamp plus the clock offset).
  void AddPose(const SE3d& world_from_radar, const Eigen::Matrix<double, 6, 6>& information);
  void AddVelocity(const Eigen::Vector3d& radar_velocity, const Eigen::Matrix3d& covariance,
                   double elevation_bias_removed = 0.0);
  WindowSolveSummary Solve();
  // After a Solve: costs a dense inverse of the window's matrix.
  WindowUncertainty Uncertainty() const;

  std::size_t size() const;
  InertialState state(std::size_t index) const;  // 0: the oldest in the window
  InertialState newest() const;
  // The newest state's radar pose in the matcher's world: A T_world_imu T_imu_radar.
  SE3d RadarPoseInMatcherWorld() const;
  SE3d radar_from_imu() const;
  Eigen::Vector2d tilt() const;   // rad: roll, pitch of the matcher's world against gravity
  double clock_offset() const;    // s: the IMU's stamps minus the radar's
  double elevation_bias() const;  // rad: how much too high the radar's elevations read
  void set_tilt(const Eigen::Vector2d& roll_pitch);
  const InertialWindowOptions& options() const { return options_; }

 private:
  struct Node;
  struct Impl;
  void RemoveOldest();
  InertialWindowOptions options_;
  std::unique_ptr<Impl> impl_;
};

// The first state and the tilt of the matcher's world, from the first scan:
// its matched T_world_radar, its Doppler velocity (radar frame) and the IMU
// samples within span / 2 of it (plus the clock offset), whose mean specific force is taken for
// gravity's reaction (the acceleration as zero: a 0.1 m/s^2 one tilts the
// start by 0.6 deg, which the window then corrects). Biases start at zero.
// Throws DataError when no sample lies within span / 2.
struct InertialStart {
  InertialState state;
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();  // rad: roll, pitch
};
InertialStart StartFromGravity(const std::vector<ImuSample>& samples, double stamp, const SE3d& world_from_radar,
                               const Eigen::Vector3d& radar_velocity, const SE3d& radar_from_imu, double span = 0.2,
                               double clock_offset = 0.0);

}  // namespace radargauss
