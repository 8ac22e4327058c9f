// SPDX-License-Identifier: BSD-3-Clause
// Radar-inertial odometry (docs/design.md, "Radar-inertial odometry") on a
// simulated drive with a MEMS IMU: its drift below the radar's alone, the
// window's gyro bias near the truth, the same trajectory for the same input
// and in SLAM's front end, and an IMU that ends before the scans refused.
#include <gtest/gtest.h>

#include "radargauss/error.hpp"
#include "radargauss/evaluation.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/simulator.hpp"
#include "radargauss/slam/radar_slam.hpp"

namespace radargauss {
namespace {

// 20 s of the demo world (its attitude wobble and elevation noise), an IMU at 200 Hz.
const SimulatedSequence& Drive() {
  static const SimulatedSequence* sequence = [] {
    SimulationConfig config;
    config.scans = 200;
    config.imu_rate_hz = 200.0;
    return new SimulatedSequence(Simulate(config));
  }();
  return *sequence;
}

double RelativeError(const Trajectory& estimate) {
  return EvaluateTrajectory(estimate, Drive().ground_truth).rpe_mean.translation;
}

TEST(RadarInertialOdometry, DriftsLessThanTheRadarAlone) {
  const SimulatedSequence& s = Drive();
  const Sequence sequence = AsSequence(s);
  RadarOdometry radar(OdometryOptions{});
  RadarInertialOdometry inertial(OdometryOptions{}, RadarInertialOptions{}, s.radar_from_imu, s.imu);
  for (const RadarScan& scan : sequence.scans) {
    radar.Register(scan);
    inertial.Register(scan);
  }
  const double radar_rpe = RelativeError(radar.trajectory());
  const double inertial_rpe = RelativeError(inertial.odometry().trajectory());
  EXPECT_LT(inertial_rpe, 0.6 * radar_rpe) << inertial_rpe << " % against " << radar_rpe << " %";
  ASSERT_TRUE(inertial.states().back().has_value());
  const Eigen::Vector3d true_gyro = s.imu_bias.back().gyro;
  EXPECT_LT((inertial.states().back()->bias.gyro - true_gyro).norm(), 0.3 * true_gyro.norm());

  // The same input, the same trajectory.
  RadarInertialOdometry again(OdometryOptions{}, RadarInertialOptions{}, s.radar_from_imu, s.imu);
  for (const RadarScan& scan : sequence.scans) again.Register(scan);
  const auto& a = inertial.odometry().steps();
  const auto& b = again.odometry().steps();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].pose.translation(), b[k].pose.translation()) << "scan " << k;
  }
}

// SLAM's front end with UseImu is the same radar-inertial odometry, scan for scan.
TEST(RadarInertialOdometry, SlamsFrontEndIsTheSame) {
  const SimulatedSequence& s = Drive();
  const Sequence sequence = AsSequence(s);
  RadarInertialOdometry inertial(OdometryOptions{}, RadarInertialOptions{}, s.radar_from_imu, s.imu);
  RadarSlam slam;
  slam.UseImu(RadarInertialOptions{}, s.radar_from_imu, s.imu);
  for (std::size_t k = 0; k < 60; ++k) {
    inertial.Register(sequence.scans[k]);
    slam.Register(sequence.scans[k]);
    ASSERT_EQ(inertial.odometry().steps()[k].pose.translation(), slam.odometry().steps()[k].pose.translation())
        << "scan " << k;
  }
  ASSERT_NE(slam.inertial(), nullptr);
  EXPECT_EQ(slam.inertial()->states().back()->bias.gyro, inertial.states().back()->bias.gyro);
}

TEST(RadarInertialOdometry, AnImuThatEndsEarlyIsRefused) {
  const SimulatedSequence& s = Drive();
  const Sequence sequence = AsSequence(s);
  const std::vector<ImuSample> first_second(s.imu.begin(), s.imu.begin() + 200);
  RadarInertialOdometry inertial(OdometryOptions{}, RadarInertialOptions{}, s.radar_from_imu, first_second);
  try {
    for (const RadarScan& scan : sequence.scans) inertial.Register(scan);
    FAIL() << "no error";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("the IMU"), std::string::npos) << e.what();
  }
}

// 30 s of the demo world with the faults of configs/synthetic_realistic.yaml
// (the radar mounted 0.5 / 1.5 / -1 deg, its elevations 0.5 deg high) and
// the IMU's stamps 20 ms late. From a nominal (identity) T_radar_imu, a zero
// clock offset and no elevation bias, with the vehicle's motion term (the
// IMU sits aligned with the vehicle): the bias within 0.15 deg, the clock
// offset within 5 ms, the mounting's pitch and yaw within 0.15 deg, its
// roll, which only the turns show, within 1.5 deg; and the drift at most
// 0.6x the radar's alone with the true mounting given.
TEST(RadarInertialOdometry, CalibratesTheMountingClockOffsetAndElevationBias) {
  SimulationConfig config =
      LoadSimulationConfig(std::string(RADARGAUSS_SOURCE_DIR) + "/configs/synthetic_realistic.yaml");
  config.scans = 300;
  config.imu_rate_hz = 200.0;
  config.imu_clock_offset = 0.020;
  ASSERT_EQ(config.elevation_bias_deg, 0.5);
  ASSERT_EQ(config.mounting_pitch_deg, 1.5);
  const SimulatedSequence s = Simulate(config);
  const Sequence sequence = AsSequence(s);
  OdometryOptions odometry;
  odometry.elevation_bias.estimate = true;
  RadarInertialOptions options;
  options.window.estimate_extrinsic_rotation = true;
  options.window.estimate_clock_offset = true;
  options.window.vehicle_motion_std = 0.1;
  RadarInertialOdometry inertial(odometry, options, SE3d(), s.imu);
  OdometryOptions mounted = odometry;
  mounted.mounting_deg = Eigen::Vector3d(config.mounting_roll_deg, config.mounting_pitch_deg, config.mounting_yaw_deg);
  RadarOdometry radar(mounted);
  for (const RadarScan& scan : sequence.scans) {
    inertial.Register(scan);
    radar.Register(scan);
  }
  constexpr double kDeg = 180.0 / M_PI;
  EXPECT_NEAR(inertial.window().elevation_bias() * kDeg, 0.5, 0.15);
  EXPECT_NEAR(inertial.window().clock_offset(), 0.020, 0.005);
  // On the right of R_radar_imu: x is the radar's roll axis, y its pitch, z its yaw.
  const Eigen::Vector3d error =
      (s.radar_from_imu.rotation().Inverse() * inertial.window().radar_from_imu().rotation()).Log() * kDeg;
  EXPECT_LT(std::abs(error.y()), 0.15) << error.transpose();
  EXPECT_LT(std::abs(error.z()), 0.15) << error.transpose();
  EXPECT_LT(std::abs(error.x()), 1.5) << error.transpose();
  const double radar_rpe = EvaluateTrajectory(radar.trajectory(), s.ground_truth).rpe_mean.translation;
  const double inertial_rpe = EvaluateTrajectory(inertial.odometry().trajectory(), s.ground_truth).rpe_mean.translation;
  EXPECT_LT(inertial_rpe, 0.6 * radar_rpe) << inertial_rpe << " % against " << radar_rpe << " %";
}

}  // namespace
}  // namespace radargauss
