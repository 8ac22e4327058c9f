// SPDX-License-Identifier: BSD-3-Clause
// The sliding window of IMU states (docs/design/solvers.md, "The sliding window") on
// a simulated drive with a MEMS IMU, turned and away from the radar: from
// noisy radar poses in a tilted world and noisy Doppler velocities it
// recovers the planted biases, the world's tilt against gravity and the
// velocity, with each solver, each bias within three of its standard
// deviations; a bias past the first-order correction is integrated again;
// the start from gravity is right on a level straight; and the window
// refuses what it cannot use.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "radargauss/core/error.hpp"
#include "radargauss/residuals/radar_inertial_residuals.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "radargauss/solvers/inertial_window.hpp"

namespace radargauss {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A 120 m loop at 6 m/s, 1.5 laps; the IMU at 200 Hz with a consumer part's
// noise, turn-on biases and random walks (the simulator's defaults).
SimulationConfig WindowConfig() {
  SimulationConfig config;
  config.loop_length = 40.0;
  config.loop_width = 25.0;
  config.corner_radius = 6.0;
  config.speed = 6.0;
  config.scans = 300;
  config.min_detections = 20;
  config.max_detections = 40;
  config.poles = 2;
  config.parked_cars = 1;
  config.moving_cars = 0;
  config.mounting_pitch_deg = 1.5;
  config.imu_rate_hz = 200.0;
  config.imu_roll_deg = 180.0;
  config.imu_yaw_deg = 30.0;
  config.imu_x = -1.2;
  config.imu_y = 0.3;
  config.imu_z = 0.4;
  config.imu_gyro_bias_std = 0.005;
  config.imu_accel_bias_std = 0.05;
  return config;
}

const SimulatedSequence& Drive() {
  static const SimulatedSequence* sequence = new SimulatedSequence(Simulate(WindowConfig()));
  return *sequence;
}

const Eigen::Vector2d kTilt(1.2 * kDeg, -0.8 * kDeg);  // the matcher's world against gravity
constexpr double kPoseStdT = 0.05, kPoseStdR = 0.3 * kDeg, kVelocityStd = 0.05;

struct Result {
  InertialState last;
  ImuBias truth;
  Eigen::Vector3d true_velocity;
  Eigen::Vector2d tilt;
  WindowUncertainty uncertainty;
  double max_cost = 0.0;
  std::size_t reintegrated = 0;                               // IMU terms integrated again over the run
  double clock_offset = 0.0;                                  // s: the window's
  Eigen::Vector3d extrinsic_error = Eigen::Vector3d::Zero();  // rad: the window's T_radar_imu against the truth
};

// Feeds every scan's pose and velocity, solving after each.
// `start_error`: the rotation the window's T_radar_imu starts off by (on the right).
// `first`: the scan the window starts at (an IMU whose clock runs late has no sample before the first scan).
Result RunWindow(const InertialWindowOptions& options, const SimulatedSequence& s = Drive(),
                 const SO3d& start_error = SO3d(), std::size_t first = 0) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  const auto noise = [&](double std) -> Eigen::Vector3d { return Eigen::Vector3d(n(rng), n(rng), n(rng)) * std; };
  const SE3d tilt(TiltRotation(kTilt.data()), Eigen::Vector3d::Zero());
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  information.diagonal() << Eigen::Vector3d::Constant(1.0 / (kPoseStdT * kPoseStdT)),
      Eigen::Vector3d::Constant(1.0 / (kPoseStdR * kPoseStdR));
  const Eigen::Matrix3d velocity_covariance = Eigen::Matrix3d::Identity() * kVelocityStd * kVelocityStd;

  const SE3d radar_from_imu = s.radar_from_imu * SE3d(start_error, Eigen::Vector3d::Zero());
  InertialWindow window(options, radar_from_imu);
  window.AddImu(s.imu);
  Result result;
  for (std::size_t k = first; k < s.scans.size(); ++k) {
    const double stamp = s.scans[k].timestamp;
    Eigen::Matrix<double, 6, 1> xi;
    xi << noise(kPoseStdT), noise(kPoseStdR);
    const SE3d measured = tilt * s.ground_truth[k].pose * SE3d::Exp(xi);
    const Eigen::Vector3d velocity = s.sensor_velocity[k] + noise(kVelocityStd);
    if (k == first) {
      const InertialStart start =
          StartFromGravity(s.imu, stamp, measured, velocity, radar_from_imu, 0.2, options.clock_offset);
      window.set_tilt(start.tilt);
      window.Start(start.state);
    } else {
      window.AddState(stamp);
    }
    window.AddPose(measured, information);
    window.AddVelocity(velocity, velocity_covariance);
    const WindowSolveSummary summary = window.Solve();
    result.reintegrated += summary.reintegrated;
    if (k > first + 20) result.max_cost = std::max(result.max_cost, summary.final_cost / double(window.size()));
  }
  result.last = window.newest();
  const std::size_t sample = std::lower_bound(s.imu.begin(), s.imu.end(), s.scans.back().timestamp,
                                              [](const ImuSample& a, double t) { return a.stamp < t; }) -
                             s.imu.begin();
  result.truth = s.imu_bias[std::min(sample, s.imu_bias.size() - 1)];
  // The IMU's world velocity by a backward difference of the true trajectory.
  const double t = s.scans.back().timestamp;
  const double h = 1e-3;
  const auto imu_position = [&](double at) {
    return (*s.ground_truth.Interpolate(at) * s.radar_from_imu).translation();
  };
  result.true_velocity = (imu_position(t) - imu_position(t - h)) / h;
  result.tilt = window.tilt();
  result.uncertainty = window.Uncertainty();
  result.clock_offset = window.clock_offset();
  // On the right of R_imu_radar, as the window's tangent and its standard deviations.
  result.extrinsic_error = (s.radar_from_imu.rotation() * window.radar_from_imu().rotation().Inverse()).Log();
  return result;
}

class InertialWindowSolvers : public ::testing::TestWithParam<WindowSolver> {};

TEST_P(InertialWindowSolvers, RecoversBiasesTiltAndVelocity) {
  InertialWindowOptions options;
  options.solver = GetParam();
  const Result r = RunWindow(options);
  EXPECT_GT(r.truth.gyro.norm(), 2e-3);  // a bias worth finding
  EXPECT_LT((r.last.bias.gyro - r.truth.gyro).norm(), 1e-3)
      << r.last.bias.gyro.transpose() << " vs " << r.truth.gyro.transpose();
  EXPECT_LT((r.last.bias.accel - r.truth.accel).norm(), 0.03)
      << r.last.bias.accel.transpose() << " vs " << r.truth.accel.transpose();
  EXPECT_LT((r.tilt - kTilt).norm(), 0.05 * kDeg) << r.tilt.transpose() / kDeg;
  // Each within three of the window's standard deviations, which say something (not the priors').
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::abs(r.last.bias.gyro(i) - r.truth.gyro(i)), 3.0 * r.uncertainty.gyro_bias(i)) << "axis " << i;
    EXPECT_LT(r.uncertainty.gyro_bias(i), 1e-3);
    EXPECT_LT(std::abs(r.last.bias.accel(i) - r.truth.accel(i)), 3.0 * r.uncertainty.accel_bias(i)) << "axis " << i;
  }
  EXPECT_LT((r.last.velocity - r.true_velocity).norm(), 0.05)
      << r.last.velocity.transpose() << " vs " << r.true_velocity.transpose();
  EXPECT_LT(r.max_cost, 100.0);  // no state's terms far beyond their noise
}

INSTANTIATE_TEST_SUITE_P(EachSolver, InertialWindowSolvers,
                         ::testing::Values(WindowSolver::kCeresLm, WindowSolver::kCeresDogleg,
                                           WindowSolver::kGaussNewton),
                         [](const auto& info) {
                           std::string name = ToString(info.param);
                           name.erase(std::remove(name.begin(), name.end(), '-'), name.end());
                           return name;
                         });

// Gyro biases of several 0.01 rad/s, past the first-order correction's bound:
// the terms are integrated again at the moved bias, and the bias is found.
TEST(InertialWindow, IntegratesAgainWhenABiasMovesPastTheCorrection) {
  SimulationConfig config = WindowConfig();
  config.imu_gyro_bias_std = 0.03;
  const SimulatedSequence biased = Simulate(config);
  const Result r = RunWindow(InertialWindowOptions{}, biased);
  EXPECT_GT(r.truth.gyro.norm(), 0.02);
  EXPECT_GT(r.reintegrated, 0u);
  EXPECT_LT((r.last.bias.gyro - r.truth.gyro).norm(), 1e-3)
      << r.last.bias.gyro.transpose() << " vs " << r.truth.gyro.transpose();
}

// The radar-IMU rotation estimated online from 1.3 deg off: within 0.2 deg
// after 30 s, and within three of its standard deviations.
TEST(InertialWindow, CalibratesAPlantedRadarImuRotation) {
  InertialWindowOptions options;
  options.estimate_extrinsic_rotation = true;
  const SO3d start_error = SO3d::Exp(Eigen::Vector3d(0.5, -1.0, 0.7) * kDeg);
  const Result r = RunWindow(options, Drive(), start_error);
  EXPECT_LT(r.extrinsic_error.norm(), 0.2 * kDeg) << r.extrinsic_error.transpose() / kDeg << " deg";
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::abs(r.extrinsic_error(i)), 3.0 * r.uncertainty.extrinsic_rotation(i)) << "axis " << i;
  }
  // Held fixed at the wrong start, the rotation's error stays and the biases pay for it.
  const Result fixed = RunWindow(InertialWindowOptions{}, Drive(), start_error);
  EXPECT_GT(fixed.extrinsic_error.norm(), 1.0 * kDeg);
  EXPECT_GT((fixed.last.bias.accel - fixed.truth.accel).norm(), (r.last.bias.accel - r.truth.accel).norm());
}

// An IMU whose stamps run 20 ms ahead of the radar's: the offset estimated
// online from zero ends within 3 ms and within three of its standard
// deviations (18.7 +- 0.6 ms), and the biases are found as with synchronised
// clocks.
TEST(InertialWindow, CalibratesAPlantedClockOffset) {
  SimulationConfig config = WindowConfig();
  config.imu_clock_offset = 0.020;
  const SimulatedSequence late = Simulate(config);
  InertialWindowOptions options;
  options.estimate_clock_offset = true;
  const Result r = RunWindow(options, late, SO3d(), 1);
  EXPECT_LT(std::abs(r.clock_offset - 0.020), 0.003) << r.clock_offset;
  EXPECT_LT(std::abs(r.clock_offset - 0.020), 3.0 * r.uncertainty.clock_offset) << r.uncertainty.clock_offset;
  EXPECT_LT((r.last.bias.gyro - r.truth.gyro).norm(), 1e-3);
  const Result held = RunWindow(InertialWindowOptions{}, late, SO3d(), 1);
  // Held at zero, the 20 ms show in the velocity (the scans' Doppler against the IMU's).
  EXPECT_GT((held.last.velocity - held.true_velocity).norm(), 2.0 * (r.last.velocity - r.true_velocity).norm());
}

TEST(InertialWindow, StartFromGravityOnALevelStraight) {
  const SimulatedSequence& s = Drive();
  const SE3d tilt(TiltRotation(kTilt.data()), Eigen::Vector3d::Zero());
  const InertialStart start = StartFromGravity(s.imu, s.scans[0].timestamp, tilt * s.ground_truth[0].pose,
                                               s.sensor_velocity[0], s.radar_from_imu);
  // The accelerometer's turn-on bias tilts it by up to |b_a| / g.
  const double bias_tilt = s.imu_bias.front().accel.norm() / kGravity;
  EXPECT_LT((start.tilt - kTilt).norm(), bias_tilt + 0.05 * kDeg);
  const Eigen::Vector3d true_velocity = (s.ground_truth[0].pose * s.radar_from_imu).rotation() *
                                        (s.radar_from_imu.Inverse().rotation() * s.sensor_velocity[0]);
  EXPECT_LT((start.state.velocity - true_velocity).norm(), 6.0 * bias_tilt + 0.05);
}

TEST(InertialWindow, RefusesWhatItCannotUse) {
  const SimulatedSequence& s = Drive();
  InertialWindow window(InertialWindowOptions{}, s.radar_from_imu);
  EXPECT_THROW(window.AddState(1.0), std::logic_error);
  window.AddImu({s.imu.begin(), s.imu.begin() + 10});
  EXPECT_THROW(window.AddImu({s.imu.front()}), DataError);  // not after the last
  InertialState first;
  first.stamp = s.imu.front().stamp;
  window.Start(first);
  EXPECT_THROW(window.AddState(first.stamp - 0.1), DataError);
  EXPECT_THROW(window.AddState(first.stamp + 1.0), DataError);  // beyond the IMU's end
  EXPECT_THROW(window.AddVelocity(Eigen::Vector3d(NAN, 0, 0), Eigen::Matrix3d::Identity()), std::invalid_argument);
  InertialWindow unstarted(InertialWindowOptions{}, s.radar_from_imu);
  InertialState nan_state;
  nan_state.velocity.x() = NAN;
  EXPECT_THROW(unstarted.Start(nan_state), std::invalid_argument);
  InertialWindowOptions bad;
  bad.size = 1;
  EXPECT_THROW(InertialWindow(bad, SE3d()), std::invalid_argument);
}

}  // namespace
}  // namespace radargauss
