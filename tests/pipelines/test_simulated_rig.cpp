// SPDX-License-Identifier: BSD-3-Clause
// A simulated rig: its radars' scans on their own clocks over one drive,
// the rig file it writes, and the rig's twist from their Doppler against the
// radars' true velocities; its config's refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <tuple>
#include <string>
#include <vector>

#include "radargauss/core/error.hpp"
#include "radargauss/core/rig_twist.hpp"
#include "radargauss/experiment/evaluation.hpp"
#include "radargauss/io/rig.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/odometry/rig_calibration.hpp"
#include "radargauss/odometry/rig_odometry.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "support/simulated_rig.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

using testing::CalibrationErrors;
using testing::Corner;
using testing::FourCorners;
using testing::FrontAndFastCorner;
using testing::RegisterOnTheBodysClock;
using testing::TrueRig;

// At every instant of the drive the rig's twist from the four radars'
// Doppler gives each radar's true velocity (R_i^T (v + w x t_i), the
// simulator's own, lever arm included) to a few centimetres per second:
// within 3 sigma of the twist's covariance for 97 % of the scans.
TEST(SimulatedRig, TheRigsTwistGivesEachRadarsTrueVelocity) {
  const SimulatedRig rig = SimulateRig(FourCorners(120));
  ASSERT_EQ(rig.radars.size(), 4u);
  std::size_t within = 0, checked = 0;
  std::vector<double> errors, twist_velocity_errors, twist_rate_errors;
  std::size_t twist_within = 0;
  for (std::size_t k = 0; k < rig.radars[0].scans.size(); ++k) {
    std::vector<RigScan> scans;
    for (std::size_t r = 0; r < 4; ++r) {
      ASSERT_EQ(rig.radars[r].scans[k].timestamp, rig.radars[0].scans[k].timestamp);  // one instant
      scans.push_back({&rig.radars[r].scans[k], rig.body_from_radar[r]});
    }
    const RigTwist twist = EstimateRigTwist(scans);
    ASSERT_TRUE(twist.success) << k << ": " << twist.reason;
    ASSERT_EQ(twist.rank, 6) << k;
    twist_velocity_errors.push_back((twist.velocity - rig.body_velocity[k]).norm());
    twist_rate_errors.push_back(std::abs(twist.angular_velocity.z() - rig.body_angular_velocity[k].z()));
    Vector6d twist_error;
    twist_error << twist.velocity - rig.body_velocity[k], twist.angular_velocity - rig.body_angular_velocity[k];
    twist_within += twist_error.dot(twist.covariance.ldlt().solve(twist_error)) < 20.06;  // 6 dof, 99.73 %
    for (std::size_t r = 0; r < 4; ++r) {
      const SE3d& mounting = rig.body_from_radar[r];
      // The radar's velocity as a linear map of the twist: J [v; w], J = R^T [I, -[t]x].
      Eigen::Matrix<double, 3, 6> J;
      J << mounting.rotation().Matrix().transpose(),
          -mounting.rotation().Matrix().transpose() * SO3d::Hat(mounting.translation());
      Vector6d x;
      x << twist.velocity, twist.angular_velocity;
      const Eigen::Vector3d error = J * x - rig.radars[r].sensor_velocity[k];
      const Eigen::Matrix3d covariance = J * twist.covariance * J.transpose();
      errors.push_back(error.norm());
      within += error.dot(covariance.ldlt().solve(error)) < 14.16;  // chi-square, 3 dof, 99.73 %
      ++checked;
    }
  }
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.03);  // m/s, median
  // And the body's own true twist (the simulator's, at the scans' instant):
  // the roll and pitch rates are seen only through the few metres between
  // the radars and the points' small elevations, so they are checked
  // against their covariance and the yaw rate to 5 mrad/s.
  std::sort(twist_velocity_errors.begin(), twist_velocity_errors.end());
  std::sort(twist_rate_errors.begin(), twist_rate_errors.end());
  EXPECT_LT(twist_velocity_errors[twist_velocity_errors.size() / 2], 0.03);  // m/s
  EXPECT_LT(twist_rate_errors[twist_rate_errors.size() / 2], 0.005);         // rad/s, the yaw rate
  EXPECT_GE(double(twist_within), 0.97 * double(rig.radars[0].scans.size()));
  EXPECT_GE(double(within), 0.97 * double(checked));
}

// Radars at their own rates and clocks: the files carry each radar's
// stamps, the rig file its mounting and offset, and on the body's clock
// every radar's scans span the drive from the same start.
class SimulatedRigFiles : public testing::TempDirTest {};

TEST_F(SimulatedRigFiles, WritesEachRadarOnItsClockAndTheRigFile) {
  RigSimulationConfig config = FourCorners(20);
  config.radars[1].second.rate_hz = 20.0;
  config.radars[2].second.clock_offset = 0.021;
  const SimulatedRig rig = SimulateRig(config);
  EXPECT_EQ(rig.radars[0].scans.size(), 20u);
  EXPECT_EQ(rig.radars[1].scans.size(), 40u);
  EXPECT_NEAR(rig.radars[2].scans.front().timestamp - rig.radars[0].scans.front().timestamp, 0.021, 1e-6);
  WriteSimulatedRig(Path("rig"), rig);
  const Rig read = ReadRig(Path("rig/rig.yaml"));
  ASSERT_EQ(read.radars.size(), 4u);
  EXPECT_EQ(read.radars[2].name, "rear_left");
  EXPECT_DOUBLE_EQ(read.radars[2].clock_offset, 0.021);
  EXPECT_LT((read.radars[3].body_from_radar.translation() - Eigen::Vector3d(-0.9, -0.9, 0.5)).norm(), 1e-12);
  std::vector<double> first(4, -1.0);
  std::size_t scans = 0;
  ForEachRigScan(read, [&](std::size_t radar, RadarScan& scan, const std::string&) {
    if (first[radar] < 0.0) first[radar] = scan.timestamp;
    ++scans;
  });
  EXPECT_EQ(scans, 20u + 40u + 20u + 20u);
  for (std::size_t r = 1; r < 4; ++r) EXPECT_NEAR(first[r], first[0], 1e-6) << r;  // one start on the body's clock
  const Trajectory body = ReadTum(Path("rig/gt_body_tum.txt"));
  EXPECT_TRUE(std::filesystem::exists(Path("rig/twist_body.txt")));
  ASSERT_EQ(body.size(), 20u);
  // The first radar's true pose is the body's times its mounting.
  const SE3d radar = *rig.radars[0].ground_truth.Interpolate(rig.radars[0].scans[5].timestamp);
  const SE3d composed = *body.Interpolate(rig.radars[0].scans[5].timestamp) * rig.body_from_radar[0];
  EXPECT_LT((radar.translation() - composed.translation()).norm(), 1e-6);
}

// A rig of one radar is the single-radar odometry bit for bit, its poses
// moved to the body; a front radar with a corner radar beside it gives one
// trajectory whose scans hold both radars' static points.
TEST(RigOdometry, OneRadarIsTheSingleRadarOdometryAndTwoShareOneMap) {
  RigSimulationConfig config;
  config.world.scans = 80;
  SimulationConfig front;
  front.mounting_x = 3.7;
  front.mounting_z = 0.5;
  config.radars = {{"front", front}, {"front_left", Corner(3.4, 0.9, 45.0)}};
  const SimulatedRig rig = SimulateRig(config);
  OdometryOptions options;
  RadarOdometry single(options);
  RigOdometry alone({rig.body_from_radar[0]}, options);
  for (const RadarScan& scan : rig.radars[0].scans) {
    single.Register(scan);
    alone.Register(0, scan);
  }
  alone.Finish();
  const Trajectory body = alone.trajectory();
  ASSERT_EQ(body.size(), single.steps().size());
  const SE3d& mounting = rig.body_from_radar[0];
  for (std::size_t k = 0; k < body.size(); ++k) {
    const SE3d expected = mounting * single.steps()[k].pose * mounting.Inverse();
    ASSERT_EQ(body[k].pose.translation(), expected.translation()) << k;
  }
  RigOdometry both(rig.body_from_radar, options);
  RegisterOnTheBodysClock(both, rig, config);
  ASSERT_EQ(both.frame_radars().size(), 80u);  // both at 10 Hz on one clock: every frame holds two scans
  EXPECT_EQ(both.frame_radars()[5], (std::vector<std::size_t>{0, 1}));
  EXPECT_GT(both.odometry().steps()[40].points, single.steps()[40].static_points);
  const Evaluation evaluation = EvaluateTrajectory(both.trajectory(), rig.body);
  EXPECT_LT(evaluation.ate_translation.rmse, 0.5);
  EXPECT_THROW(both.Register(2, rig.radars[0].scans[0]), DataError);
}

// A corner radar at twice the front radar's rate, on its own clock: each
// frame closes at the front radar's scan and holds the corner's two scans
// since the last; the rig's twist measures the velocity.
TEST(RigOdometry, FramesCloseAtTheReferenceRadarsScan) {
  const RigSimulationConfig config = FrontAndFastCorner(100);
  const SimulatedRig rig = SimulateRig(config);
  RigOdometry odometry(rig.body_from_radar);
  RegisterOnTheBodysClock(odometry, rig, config);
  ASSERT_EQ(odometry.frame_radars().size(), 101u);  // the corner's last scan comes after the front's last
  EXPECT_EQ(odometry.frame_radars()[0], (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(odometry.frame_radars()[7], (std::vector<std::size_t>{1, 0, 1}));
  EXPECT_GE(odometry.rig_velocity_measured(), 90u);
  EXPECT_LT(EvaluateTrajectory(odometry.trajectory(), rig.body).ate_translation.rmse, 0.3);
  OdometryOptions bad;
  bad.rig.max_frame_span = 0.0;
  EXPECT_THROW(RigOdometry(rig.body_from_radar, bad), std::invalid_argument);
}

// Four corner radars observe all three rotation rates: with them as the
// rotation term's prediction the drift is less than with the term's loose
// default (90 deg/s about the vertical), by at least a third over a lap's
// first 120 scans; the rates tie roll and pitch too.
TEST(RigOdometry, TheRigsRotationRateCutsTheDrift) {
  const SimulatedRig rig = SimulateRig(FourCorners(120));
  const auto drift = [&](bool rate) {
    OdometryOptions options;
    options.rig.rotation_rate = rate ? "all" : "off";
    RigOdometry odometry(rig.body_from_radar, options);
    for (std::size_t k = 0; k < rig.radars[0].scans.size(); ++k) {
      for (std::size_t r = 0; r < rig.radars.size(); ++r) odometry.Register(r, rig.radars[r].scans[k]);
    }
    odometry.Finish();
    return EvaluateTrajectory(odometry.trajectory(), rig.body).rpe_mean.translation;
  };
  const double with_rate = drift(true), without = drift(false);
  EXPECT_LT(with_rate, 0.67 * without) << with_rate << " against " << without;
}

// One IMU on the body, turned and above its origin, its window in the front
// radar's frame (T_ref_imu = T_body_ref^-1 T_body_imu): the gravity and the
// gyro take the drift the radars leave (the vertical above all), and the
// window finds the gyro's true bias to a quarter of its size in 10 s (a
// wrong extrinsic would turn it).
TEST(RigOdometry, AnImuOnTheBodyCutsTheDriftAndFindsItsGyroBias) {
  RigSimulationConfig config = FrontAndFastCorner(100);
  config.world.imu_rate_hz = 200.0;
  config.world.imu_yaw_deg = 90.0;
  config.world.imu_z = 0.3;  // above the origin: ahead of it the path's yaw-rate steps make impulses
  const SimulatedRig rig = SimulateRig(config);
  ASSERT_FALSE(rig.imu.empty());
  const auto drift = [&](RigOdometry& odometry) {
    RegisterOnTheBodysClock(odometry, rig, config);
    return EvaluateTrajectory(odometry.trajectory(), rig.body).rpe_mean.translation;
  };
  RigOdometry radars(rig.body_from_radar);
  RigOdometry inertial(rig.body_from_radar, {},
                       MakeMotionModel({}, rig.body_from_radar.front().Inverse() * rig.body_from_imu, rig.imu));
  const double without = drift(radars), with_imu = drift(inertial);
  EXPECT_LT(with_imu, 0.5 * without) << with_imu << " against " << without;
  const InertialMotion* window = InertialMotionOf(inertial.odometry());
  ASSERT_TRUE(window && !window->states().empty() && window->states().back());
  const Eigen::Vector3d error = window->states().back()->bias.gyro - rig.imu_bias.back().gyro;
  EXPECT_LT(error.norm(), 0.25 * rig.imu_bias.back().gyro.norm())
      << error.transpose() << " (true " << rig.imu_bias.back().gyro.transpose() << ")";
}

// Planted by hand: the body drives straight at 10 m/s past static points; a
// corner radar scans 50 ms before the front radar. The frame's points are
// where the world's points lie in the front radar's frame at its stamp, to
// 1e-9 (the rig's twist from exact Doppler moves the corner's scan); without
// the motion they lag by the 0.5 m driven between.
TEST(RigOdometry, AnOlderScanIsMovedToTheFramesStamp) {
  const std::vector<SE3d> mountings = {
      SE3d(SO3d(), Eigen::Vector3d(3.7, 0.0, 0.5)),
      SE3d(SO3d::Exp(Eigen::Vector3d(0.0, 0.0, M_PI / 4.0)), Eigen::Vector3d(3.4, 0.9, 0.5))};
  const Eigen::Vector3d velocity(10.0, 0.0, 0.0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> x(-40.0, 60.0), y(-30.0, 30.0), z(-2.0, 4.0);
  std::vector<Eigen::Vector3d> world(300);
  for (Eigen::Vector3d& point : world) point = Eigen::Vector3d(x(rng), y(rng), z(rng));
  const auto scan_at = [&](std::size_t radar, double stamp) {
    const SE3d world_from_radar = SE3d(SO3d(), velocity * stamp) * mountings[radar];
    RadarScan scan;
    scan.timestamp = stamp;
    scan.has_doppler = true;
    for (const Eigen::Vector3d& w : world) {
      RadarPoint point;
      point.position = world_from_radar.Inverse() * w;
      point.doppler = RigDoppler(point.position, mountings[radar], velocity, Eigen::Vector3d::Zero());
      scan.points.push_back(point);
    }
    return scan;
  };
  for (const bool move : {true, false}) {
    OdometryOptions options;
    options.rig.motion_compensation = move;
    RigOdometry odometry(mountings, options);
    odometry.Register(1, scan_at(1, 0.95));
    odometry.Register(0, scan_at(0, 1.0));
    odometry.Finish();
    ASSERT_EQ(odometry.rig_velocity_measured(), 1u);
    const RadarScan& frame = odometry.last_frame();
    ASSERT_EQ(frame.points.size(), 2 * world.size());
    const SE3d front_at_stamp = SE3d(SO3d(), velocity * 1.0) * mountings[0];
    double worst = 0.0;
    for (std::size_t i = 0; i < world.size(); ++i) {
      worst = std::max(worst, (frame.points[i].position - front_at_stamp.Inverse() * world[i]).norm());
      EXPECT_LT((frame.points[world.size() + i].position - front_at_stamp.Inverse() * world[i]).norm(), 1e-9);
    }
    EXPECT_NEAR(worst, move ? 0.0 : 0.5, 1e-9);
  }
}

// A front radar and a front corner radar over 20 s. Given the truth, the
// calibration against the front radar stays within 0.3 deg, 3 cm and 6 ms
// of it (it is biased: the reference's odometry lags the true rotation
// rate). Given 2 deg, 5 cm and 20 ms off, it brings the corner within
// 0.5 deg, 3 cm and 10 ms. The goals of 0.2 deg, 3 cm and 2 ms are not
// reached (bench/RESULTS.md, "Radar rigs").
TEST(RigCalibration, StaysAtTheTruthAndBringsAGivenOffCornerRadarCloser) {
  const RigSimulationConfig config = FrontAndFastCorner(200);
  const SimulatedRig simulated = SimulateRig(config);
  const Rig truth = TrueRig(config, simulated);
  const std::vector<std::vector<RadarScan>> scans = {simulated.radars[0].scans, simulated.radars[1].scans};
  const auto errors = [&](const Rig& calibrated) { return CalibrationErrors(truth, calibrated); };
  const RigCalibration at_truth = CalibrateRig(truth, scans);
  EXPECT_LT(errors(at_truth.rig).x(), 0.3);
  EXPECT_LT(errors(at_truth.rig).y(), 0.03);
  EXPECT_LT(errors(at_truth.rig).z(), 0.006);
  const Rig given = testing::GivenOff(truth);
  const RigCalibration calibration = CalibrateRig(given, scans);
  ASSERT_EQ(calibration.radars.size(), 2u);
  EXPECT_LT(errors(calibration.rig).x(), 0.5);
  EXPECT_LT(errors(calibration.rig).y(), 0.03);
  EXPECT_LT(errors(calibration.rig).z(), 0.01);
  EXPECT_TRUE(calibration.radars[1].rotation_std.allFinite());
  EXPECT_GT(calibration.radars[1].map_points, 1000u);
  // The reference stays as given; the scans must be the rig's.
  EXPECT_EQ(calibration.rig.radars[0].body_from_radar.translation(), given.radars[0].body_from_radar.translation());
  EXPECT_THROW(CalibrateRig(given, {scans[0]}), DataError);
}

// With an IMU on the body, the reference's odometry runs with its window
// and its angular velocity comes from the gyro: from the truth the corner
// radar stays within the bounds of the calibration without it. An IMU that
// covers none of the drive is refused.
TEST(RigCalibration, WithAnImuTheRatesComeFromTheGyroWhereItsWindowRan) {
  RigSimulationConfig config = FrontAndFastCorner(200);
  config.world.imu_rate_hz = 200.0;
  const SimulatedRig simulated = SimulateRig(config);
  const Rig truth = TrueRig(config, simulated);
  const std::vector<std::vector<RadarScan>> scans = {simulated.radars[0].scans, simulated.radars[1].scans};
  const RigCalibration calibration = CalibrateRig(truth, scans, {}, RigImu{simulated.imu, simulated.body_from_imu, {}});
  EXPECT_TRUE(calibration.gyro);
  const Eigen::Vector3d errors = CalibrationErrors(truth, calibration.rig);
  EXPECT_LT(errors.x(), 0.3);
  EXPECT_LT(errors.y(), 0.03);
  EXPECT_LT(errors.z(), 0.006);
  std::vector<ImuSample> early(simulated.imu.begin(), simulated.imu.begin() + 100);
  for (ImuSample& sample : early) sample.stamp -= 100.0;  // before the first scan
  EXPECT_THROW(CalibrateRig(truth, scans, {}, RigImu{early, simulated.body_from_imu, {}}), DataError);
}

TEST_F(SimulatedRigFiles, ItsConfigRefusesWhatIsTheRigsOwn) {
  const auto error_of = [&](const std::string& text) {
    const std::string path = WriteFile("rig.yaml", text);
    try {
      LoadRigSimulationConfig(path);
    } catch (const DataError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("radars:\n  - {name: a, loop_length: 50}\n").find("loop_length: radar 'a' sets a key of the rig"),
            std::string::npos);
  EXPECT_NE(error_of("radars:\n  - {mounting_x: 1}\n").find("radar 1 needs a name"), std::string::npos);
  EXPECT_NE(error_of("radars:\n  - {name: a}\n  - {name: a}\n").find("two radars are named 'a'"), std::string::npos);
  EXPECT_NE(error_of("radars:\n  - {name: a, imu_x: 1}\n").find("imu_x: radar 'a' sets a key of the rig"),
            std::string::npos);
  EXPECT_NE(error_of("radars: []\n").find("no radars"), std::string::npos);
  EXPECT_NE(error_of("radars:\n  - {name: a, mounting_yaw_deg: 270}\n").find("mounting_yaw_deg"), std::string::npos);
  EXPECT_EQ(error_of("world: {scans: 10}\nradars:\n  - {name: a, clock_offset: 0.01}\n"), "no error");
  const RigSimulationConfig ok = LoadRigSimulationConfig(Path("rig.yaml"));
  EXPECT_EQ(ok.world.scans, 10);
  EXPECT_DOUBLE_EQ(ok.radars[0].second.clock_offset, 0.01);
}

}  // namespace
}  // namespace radargauss
