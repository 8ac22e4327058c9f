// SPDX-License-Identifier: BSD-3-Clause
// The online calibration of a rig: on a planted drive (the reference's exact
// motion, a second radar's Doppler at its true mounting and clock) it finds
// the planted mounting from one given off, and moves only what the drive
// observes; on a simulated rig it runs inside the rig's odometry.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

#include "radargauss/odometry/rig_online_calibration.hpp"
#include "support/simulated_rig.hpp"

namespace radargauss {
namespace {

constexpr double kDegree = M_PI / 180.0;

// A planted drive of the reference radar: its velocity v(t) and angular
// velocity w(t) in its own frame, its pose integrated from them.
struct PlantedDrive {
  double speed = 10.0, speed_swing = 0.0, yaw_rate = 0.0;  // v_x = speed + swing sin(0.7 t), w_z = rate sin(0.5 t)
  Eigen::Vector3d Velocity(double t) const { return {speed + speed_swing * std::sin(0.7 * t), 0.0, 0.0}; }
  Eigen::Vector3d AngularVelocity(double t) const { return {0.0, 0.0, yaw_rate * std::sin(0.5 * t)}; }
};

// The true second radar: yawed 60 deg and pitched 3 deg, 1 m behind, 0.8 m left.
SE3d TrueMounting() {
  return SE3d(
      SO3d::Exp(Eigen::Vector3d(0.0, 0.0, 60.0 * kDegree)) * SO3d::Exp(Eigen::Vector3d(0.0, 3.0 * kDegree, 0.0)),
      Eigen::Vector3d(-1.0, 0.8, 0.2));
}

// `seconds` of the drive: the reference's frames at 10 Hz, the second radar's
// scans at 20 Hz taken at true times t and stamped t + clock_error, 40
// static points each with Doppler noise of 0.02 m/s.
void Drive(RigOnlineCalibration& calibration, const PlantedDrive& drive, double seconds, double clock_error,
           std::size_t& updates) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> azimuth(-1.0, 1.0), elevation(-0.15, 0.15), range(10.0, 50.0);
  std::normal_distribution<double> noise(0.0, 0.02);
  const SE3d mounting = TrueMounting();
  SE3d pose;
  double t = 0.0, next_scan = 0.013;
  constexpr double kStep = 1e-3;
  for (int frame = 0; frame * 0.1 <= seconds; ++frame) {
    const double stamp = frame * 0.1;
    for (; t < stamp - 0.5 * kStep; t += kStep) {  // the pose at the frame's stamp
      Eigen::Matrix<double, 6, 1> twist;
      twist << drive.Velocity(t + 0.5 * kStep), drive.AngularVelocity(t + 0.5 * kStep);
      pose = pose * SE3d::Exp(twist * kStep);
    }
    for (; next_scan + clock_error <= stamp; next_scan += 0.05) {  // the scans stamped up to this frame
      RadarScan scan;
      scan.timestamp = next_scan + clock_error;
      scan.has_doppler = true;
      const Eigen::Vector3d v =
          mounting.rotation().Inverse() *
          (drive.Velocity(next_scan) + drive.AngularVelocity(next_scan).cross(mounting.translation()));
      for (int i = 0; i < 40; ++i) {
        const double a = azimuth(rng), e = elevation(rng);
        const Eigen::Vector3d u(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
        RadarPoint point;
        point.position = range(rng) * u;
        point.doppler = -u.dot(v) + noise(rng);
        scan.points.push_back(point);
      }
      calibration.AddScan(1, scan, std::vector<bool>(scan.points.size(), true));
    }
    calibration.AddReference(stamp, pose, drive.Velocity(stamp));
    updates += calibration.Update();
  }
}

RigOdometryOptions CalibrationOn() {
  RigOdometryOptions options;
  options.calibrate = true;
  return options;
}

// Turns and changes of speed observe the rotation (about the velocity through
// the lever arm only, to 0.5 deg here), the translation across the yaw axis
// and the clock: from 2 deg, 5 cm and 20 ms off, the estimate comes to the
// planted mounting within 0.5 deg (3 sigma of its std), 1 cm and 2 ms. A yaw
// alone never shows the height of the lever arm: it stays as given.
TEST(RigOnlineCalibration, TurnsAndChangesOfSpeedBringTheGivenMountingToThePlantedOne) {
  const SE3d truth = TrueMounting();
  const SE3d given(truth.rotation() * SO3d::Exp(Eigen::Vector3d(1.0, -1.0, 1.0).normalized() * (2.0 * kDegree)),
                   truth.translation() + 0.05 * Eigen::Vector3d(-1.0, 1.0, 1.0).normalized());
  RigOdometryOptions options = CalibrationOn();
  options.calibration_observed(0) = 0.5;  // the rotation about the velocity: seen through the lever arm only
  RigOnlineCalibration calibration({SE3d(), given}, options);
  PlantedDrive drive;
  drive.speed_swing = 2.0;
  drive.yaw_rate = 0.4;
  std::size_t updates = 0;
  Drive(calibration, drive, 40.0, 0.020, updates);
  EXPECT_GE(calibration.windows(), 7u);
  EXPECT_GE(updates, 7u);
  const SE3d& estimate = calibration.reference_from_radar(1);
  const Eigen::Vector3d rotation_error = (truth.rotation().Inverse() * estimate.rotation()).Log();
  const Eigen::Vector3d translation_error = estimate.translation() - truth.translation();
  const double clock_error = calibration.clock_change(1) - 0.020;
  const RigOnlineCalibration::Vector7d std = calibration.std(1);
  EXPECT_LT(rotation_error.norm(), 0.5 * kDegree);
  EXPECT_LT(translation_error.head<2>().norm(), 0.01);
  EXPECT_LT(std::abs(clock_error), 0.002);
  for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(rotation_error(k)), 3.0 * std(k)) << "rotation " << k;
  EXPECT_NEAR(estimate.translation().z(), given.translation().z(), 1e-6);
  EXPECT_NEAR(std(5), 0.1, 1e-3);  // the height's std stays about the prior's
  EXPECT_EQ(calibration.observed_directions(1), Eigen::Vector3i(3, 2, 1));
}

// A straight drive at a constant speed observes the rotation but about the
// velocity's axis, no lever arm and no clock: those stay exactly as given.
TEST(RigOnlineCalibration, AStraightDriveMovesOnlyWhatItObserves) {
  const SE3d truth = TrueMounting();
  const Eigen::Vector3d off(0.02, 0.0, 0.03);  // rad about the reference's x (the velocity) and z
  const SE3d given(SO3d::Exp(off) * truth.rotation(), truth.translation() + Eigen::Vector3d(0.03, -0.04, 0.02));
  RigOnlineCalibration calibration({SE3d(), given}, CalibrationOn());
  std::size_t updates = 0;
  Drive(calibration, PlantedDrive{}, 20.0, 0.020, updates);
  EXPECT_GE(updates, 3u);
  const SE3d& estimate = calibration.reference_from_radar(1);
  const Eigen::Vector3d left = (estimate.rotation() * truth.rotation().Inverse()).Log();
  EXPECT_NEAR(left.x(), off.x(), 0.05 * kDegree);  // about the velocity: held
  EXPECT_NEAR(left.y(), 0.0, 0.1 * kDegree);
  EXPECT_NEAR(left.z(), 0.0, 0.1 * kDegree);
  EXPECT_LT((estimate.translation() - given.translation()).norm(), 1e-6);
  EXPECT_NEAR(calibration.clock_change(1), 0.0, 1e-9);
  EXPECT_EQ(calibration.observed_directions(1), Eigen::Vector3i(2, 0, 0));
  // A bad option is refused.
  RigOdometryOptions bad = CalibrationOn();
  bad.calibration_window = 0.0;
  EXPECT_THROW(RigOnlineCalibration({SE3d(), given}, bad), std::invalid_argument);
}

// In the rig's odometry on a simulated drive of 20 s (a front radar, a corner
// at 20 Hz on its own clock), the online calibration brings the corner given
// 2 deg, 5 cm and 20 ms off to within 0.3 deg, 3 cm and 10 ms of its truth
// (0.11 deg, 1.1 cm, 5.8 ms), and the frames use the estimate.
TEST(RigOdometry, TheOnlineCalibrationBringsAGivenOffCornerCloser) {
  const RigSimulationConfig config = testing::FrontAndFastCorner(200);
  const SimulatedRig simulated = SimulateRig(config);
  const Rig truth = testing::TrueRig(config, simulated);
  const Rig given = testing::GivenOff(truth);
  OdometryOptions options;
  options.rig.calibrate = true;
  RigOdometry odometry(testing::MountingsOf(given), options);
  testing::RegisterOnTheBodysClock(odometry, simulated,
                                   std::vector<double>{given.radars[0].clock_offset, given.radars[1].clock_offset});
  const Rig calibrated = OnlineCalibratedRig(given, odometry.frames());
  const Eigen::Vector3d before = testing::CalibrationErrors(truth, given);
  const Eigen::Vector3d after = testing::CalibrationErrors(truth, calibrated);
  std::printf("online calibration: %.3f deg, %.3f m, %.1f ms (given %.3f deg, %.3f m, %.1f ms)\n", after.x(), after.y(),
              after.z() * 1e3, before.x(), before.y(), before.z() * 1e3);
  ASSERT_NE(odometry.frames().online_calibration(), nullptr);
  EXPECT_GE(odometry.frames().online_calibration()->windows(), 6u);
  EXPECT_LT(after.x(), 0.3);
  EXPECT_LT(after.y(), 0.03);
  EXPECT_LT(after.z(), 0.010);
  // The frames use the estimate.
  EXPECT_LT((odometry.frames().reference_from_radar()[1].translation() -
             (given.radars[0].body_from_radar.Inverse() * calibrated.radars[1].body_from_radar).translation())
                .norm(),
            1e-12);
}

// Until the drive observes a radar's mounting, its scans join neither the
// rig's twist nor the frames: over 3 s, shorter than a window, the frames
// are the front radar's alone, where without the calibration the rig's
// twist measures them.
TEST(RigOdometry, ARadarWaitsForItsMountingOutsideTheTwistAndTheFrames) {
  const RigSimulationConfig config = testing::FrontAndFastCorner(30);
  const SimulatedRig simulated = SimulateRig(config);
  const Rig truth = testing::TrueRig(config, simulated);
  OdometryOptions options;
  RigOdometry without(testing::MountingsOf(truth), options);
  testing::RegisterOnTheBodysClock(without, simulated, config);
  options.rig.calibrate = true;
  options.rig.calibration_window = 10.0;
  RigOdometry waiting(testing::MountingsOf(truth), options);
  testing::RegisterOnTheBodysClock(waiting, simulated, config);
  EXPECT_GT(without.rig_velocity_measured(), 20u);
  EXPECT_EQ(waiting.rig_velocity_measured(), 0u);
  EXPECT_EQ(waiting.frames().online_calibration()->windows(), 0u);
  // The frames: the front radar's points only, without the corner's.
  const auto points = [](const RigOdometry& odometry) {
    std::size_t sum = 0;
    for (const OdometryStep& step : odometry.odometry().steps()) sum += step.points;
    return sum;
  };
  EXPECT_GT(points(waiting), 1000u);
  EXPECT_LT(double(points(waiting)), 0.8 * double(points(without)));
}

}  // namespace
}  // namespace radargauss
