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

}  // namespace
}  // namespace radargauss
