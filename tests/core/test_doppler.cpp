// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/core/doppler.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "radargauss/io/sequence.hpp"
#include "radargauss/odometry/mounting.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "support/temp_dir.hpp"
#include "support/test_util.hpp"

namespace radargauss {
namespace {

using testing::RandomUnitVector;

// A scan of static points seen from a sensor moving at `velocity`, plus
// `outliers` points whose Doppler is 1..10 m/s off the static model.
RadarScan PlantedScan(const Eigen::Vector3d& velocity, int inliers, int outliers, double noise, std::mt19937& rng) {
  std::uniform_real_distribution<double> azimuth(-1.0, 1.0), elevation(-0.25, 0.25), range(2, 80), doppler(-10, 10);
  std::normal_distribution<double> normal(0.0, noise);
  RadarScan scan;
  scan.has_doppler = true;
  for (int i = 0; i < inliers + outliers; ++i) {
    const double az = azimuth(rng), el = elevation(rng);
    RadarPoint p;
    const Eigen::Vector3d u(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    p.position = range(rng) * u;
    const double off_model = (doppler(rng) > 0.0 ? 1.0 : -1.0) * (1.0 + 0.9 * std::abs(doppler(rng)));
    p.doppler = -u.dot(velocity) + (i < inliers ? normal(rng) : off_model);
    scan.points.push_back(p);
  }
  return scan;
}

TEST(EgoVelocity, RansacIterationCount) {
  // ceil(log(1 - 0.9999) / log(1 - 0.6^3)) = ceil(37.85).
  EXPECT_EQ(RansacIterations(0.4, 0.9999), 38);
  EXPECT_EQ(RansacIterations(0.0, 0.9999), 1);
}

TEST(EgoVelocity, RecoversPlantedVelocityExactlyWithoutNoise) {
  std::mt19937 rng(4);
  const Eigen::Vector3d velocity(5.0, -0.4, 0.1);
  const RadarScan scan = PlantedScan(velocity, 120, 80, 0.0, rng);
  const EgoVelocityResult result = EstimateEgoVelocity(scan);
  ASSERT_TRUE(result.success) << result.reason;
  EXPECT_LT((result.velocity - velocity).norm(), 1e-9);
  for (int i = 0; i < 120; ++i) EXPECT_TRUE(result.inlier[i]);
  int outliers_accepted = 0;
  for (int i = 120; i < 200; ++i) outliers_accepted += result.inlier[i];
  EXPECT_EQ(outliers_accepted, 0);
  EXPECT_LT(result.covariance.norm(), 1e-12);
}

TEST(EgoVelocity, CovarianceMatchesNoise) {
  std::mt19937 rng(8);
  const Eigen::Vector3d velocity(3.0, 0.5, 0.0);
  const RadarScan scan = PlantedScan(velocity, 400, 0, 0.03, rng);
  const EgoVelocityResult result = EstimateEgoVelocity(scan);
  ASSERT_TRUE(result.success);
  EXPECT_LT((result.velocity - velocity).norm(), 0.05);
  // x is well observed (forward rays): its std is close to 0.03 / sqrt(400).
  EXPECT_NEAR(std::sqrt(result.covariance(0, 0)), 0.03 / std::sqrt(400.0), 0.001);
}

TEST(EgoVelocity, ZeroVelocityBranch) {
  std::mt19937 rng(2);
  RadarScan scan = PlantedScan(Eigen::Vector3d::Zero(), 100, 0, 0.01, rng);
  scan.points[0].doppler = 3.0;  // a moving target
  const EgoVelocityResult result = EstimateEgoVelocity(scan);
  ASSERT_TRUE(result.success);
  EXPECT_TRUE(result.zero_velocity);
  EXPECT_EQ(result.velocity, Eigen::Vector3d::Zero());
  EXPECT_FALSE(result.inlier[0]);
  EXPECT_TRUE(result.inlier[1]);
}

TEST(EgoVelocity, FailsWithReasonOnDegenerateScans) {
  RadarScan scan;
  scan.has_doppler = true;
  EgoVelocityResult result = EstimateEgoVelocity(scan);
  EXPECT_FALSE(result.success);
  EXPECT_NE(result.reason.find("fewer than 3"), std::string::npos);
  RadarPoint near;
  near.position = Eigen::Vector3d(0.1, 0, 0);  // inside the 0.25 m gate
  scan.points.assign(10, near);
  EXPECT_FALSE(EstimateEgoVelocity(scan).success);
  scan.has_doppler = false;
  result = EstimateEgoVelocity(scan);
  EXPECT_FALSE(result.success);
  EXPECT_NE(result.reason.find("no Doppler"), std::string::npos);
  // All points in one direction: H is rank 1.
  scan.has_doppler = true;
  RadarPoint p;
  p.position = Eigen::Vector3d(10, 0, 0);
  p.doppler = -2.0;
  scan.points.assign(20, p);
  result = EstimateEgoVelocity(scan);
  EXPECT_FALSE(result.success);
  EXPECT_FALSE(result.reason.empty());
  EXPECT_TRUE(result.velocity.allFinite());
}

// Simulated scans with 40% dynamic / clutter points: within 0.05 m/s of the
// truth in at least 95% of scans.
TEST(EgoVelocity, SimulatedScansWithFortyPercentOutliers) {
  SimulationConfig config;
  config.scans = 120;
  config.seed = 3;
  const SimulatedSequence sequence = Simulate(config);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> doppler(-15.0, 15.0);
  int good = 0;
  for (std::size_t k = 0; k < sequence.scans.size(); ++k) {
    RadarScan scan = sequence.scans[k];
    std::size_t bad = 0;
    for (const DetectionTruth& t : sequence.truth[k]) bad += t.kind != DetectionKind::kStatic;
    // Corrupt static points' Doppler until 40% of the scan is not static.
    const std::size_t wanted = static_cast<std::size_t>(0.4 * scan.points.size());
    for (std::size_t i = 0; i < scan.points.size() && bad < wanted; ++i) {
      if (sequence.truth[k][i].kind == DetectionKind::kStatic) {
        scan.points[i].doppler = doppler(rng);
        ++bad;
      }
    }
    const EgoVelocityResult result = EstimateEgoVelocity(scan);
    good += result.success && (result.velocity - sequence.sensor_velocity[k]).norm() < 0.05;
  }
  EXPECT_GE(good, static_cast<int>(std::ceil(0.95 * sequence.scans.size()))) << good << " of " << sequence.scans.size();
}

// NTU Eagle: speed from Doppler against speed from the reference poses (the
// data README reports 0.041 m/s median with its own RANSAC).
TEST(EgoVelocityRealData, NtuEagleSpeedAgreesWithGroundTruth) {
  const std::string dir = testing::SharedData("ntu4dradlm_loop1_eagle");
  if (dir.empty()) GTEST_SKIP() << "shared data not found";
  SequenceOptions options;
  options.sequence_dir = dir + "/points";
  options.ground_truth = dir + "/gt_tum.txt";
  const Sequence sequence = LoadSequence(options);
  std::vector<double> differences;
  const double dt = 0.05;
  for (const RadarScan& scan : sequence.scans) {
    const auto before = sequence.trajectory.Interpolate(scan.timestamp - dt);
    const auto after = sequence.trajectory.Interpolate(scan.timestamp + dt);
    if (!before || !after) continue;
    const double reference_speed = (after->translation() - before->translation()).norm() / (2.0 * dt);
    const EgoVelocityResult result = EstimateEgoVelocity(scan);
    ASSERT_TRUE(result.success) << result.reason;
    differences.push_back(std::abs(result.velocity.norm() - reference_speed));
  }
  ASSERT_GT(differences.size(), 480u);
  std::nth_element(differences.begin(), differences.begin() + differences.size() / 2, differences.end());
  const double median = differences[differences.size() / 2];
  std::printf("NTU Eagle: median |speed_doppler - speed_gt| = %.4f m/s over %zu scans\n", median, differences.size());
  EXPECT_LT(median, 0.06);
}

// A view 60% filled by one moving car: its points agree on an apparent ego
// velocity v_sensor - v_car, a larger consensus than the 40% static world's.
// Plain RANSAC takes the car; gated by a prediction near the true velocity it
// keeps the world. A car ahead at the sensor's own speed reads as standstill
// (zero Doppler) unless the gate rules standstill out.
TEST(EgoVelocity, PredictionGateKeepsTheWorldWhenACarFillsTheView) {
  std::mt19937 rng(21);
  const Eigen::Vector3d sensor(10.0, 0.0, 0.0), car(4.0, 3.0, 0.0);
  RadarScan scan = PlantedScan(sensor, 40, 0, 0.02, rng);
  const RadarScan car_points = PlantedScan(sensor - car, 60, 0, 0.02, rng);  // -u.(v_s - v_car) = u.(v_car - v_s)
  scan.points.insert(scan.points.end(), car_points.points.begin(), car_points.points.end());
  const EgoVelocityResult plain = EstimateEgoVelocity(scan);
  ASSERT_TRUE(plain.success);
  EXPECT_GT((plain.velocity - sensor).norm(), 3.0);  // the car
  const VelocityGate gate{Eigen::Vector3d(9.5, 0.3, 0.0), 1.5};
  const EgoVelocityResult gated = EstimateEgoVelocity(scan, {}, gate);
  ASSERT_TRUE(gated.success) << gated.reason;
  EXPECT_LT((gated.velocity - sensor).norm(), 0.05);
  // Every static point, and of the car only the few seen across the two
  // velocities' difference (where both models give the same Doppler).
  int car_inliers = 0;
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    if (i < 40) {
      EXPECT_TRUE(gated.inlier[i]) << i;
    }
    car_inliers += i >= 40 && gated.inlier[i];
  }
  EXPECT_LT(car_inliers, 6);
  // A gate that admits neither: no estimate, a reason.
  const EgoVelocityResult none = EstimateEgoVelocity(scan, {}, VelocityGate{Eigen::Vector3d(0, 8, 0), 1.0});
  EXPECT_FALSE(none.success);
  EXPECT_NE(none.reason.find("prediction gate"), std::string::npos);
  // Zero Doppler everywhere: standstill, unless the prediction says 10 m/s.
  const RadarScan ahead = PlantedScan(Eigen::Vector3d::Zero(), 80, 0, 0.0, rng);
  EXPECT_TRUE(EstimateEgoVelocity(ahead).zero_velocity);
  const EgoVelocityResult moving = EstimateEgoVelocity(ahead, {}, VelocityGate{sensor, 1.5});
  EXPECT_FALSE(moving.zero_velocity);
  EXPECT_FALSE(moving.success);
}

// The demo sequence's first scan: a car ahead gives three quarters of the
// detections. Plain RANSAC takes it for the world; the prediction gate, and
// support counted in voxels (odometry's default), keep the world.
TEST(EgoVelocity, SimulatedCarFillingTheViewNeedsTheGateOrVoxelSupport) {
  SimulationConfig config;
  config.scans = 1;
  config.seed = 1;
  const SimulatedSequence drive = Simulate(config);
  const RadarScan& scan = drive.scans[0];
  const Eigen::Vector3d truth = drive.sensor_velocity[0];
  std::size_t moving = 0;
  for (const DetectionTruth& t : drive.truth[0]) moving += t.kind == DetectionKind::kDynamic;
  ASSERT_GT(moving, scan.points.size() / 2);
  const EgoVelocityResult plain = EstimateEgoVelocity(scan);
  ASSERT_TRUE(plain.success);
  EXPECT_GT((plain.velocity - truth).norm(), 3.0) << "the car";
  const VelocityGate gate{truth + Eigen::Vector3d(0.4, -0.3, 0.1), 1.0};
  const EgoVelocityResult gated = EstimateEgoVelocity(scan, {}, gate);
  ASSERT_TRUE(gated.success) << gated.reason;
  EXPECT_LT((gated.velocity - truth).norm(), 0.1);
  EgoVelocityOptions voxels;
  voxels.consensus_voxel = 1.0;
  const EgoVelocityResult by_voxel = EstimateEgoVelocity(scan, voxels);
  ASSERT_TRUE(by_voxel.success) << by_voxel.reason;
  EXPECT_LT((by_voxel.velocity - truth).norm(), 0.1);
  std::size_t car_inliers = 0;
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    car_inliers += gated.inlier[i] && drive.truth[0][i].kind == DetectionKind::kDynamic;
  }
  EXPECT_LT(car_inliers, moving / 10);
}

// The hypotheses' supports are counted side by side: the same velocity,
// covariance and inliers for 1, 2 and 8 threads, with and without voxels
// and the gate (equal supports go to the first hypothesis drawn).
TEST(EgoVelocity, SameEstimateForAnyThreadCount) {
  std::mt19937 rng(33);
  const Eigen::Vector3d sensor(8.0, -1.0, 0.2);
  RadarScan scan = PlantedScan(sensor, 300, 200, 0.05, rng);
  EgoVelocityOptions voxels;
  voxels.consensus_voxel = 1.0;
  const VelocityGate gate{sensor + Eigen::Vector3d(0.3, 0.2, 0.0), 1.0};
  for (const auto& [options, with_gate] :
       {std::pair{EgoVelocityOptions(), false}, std::pair{voxels, false}, std::pair{EgoVelocityOptions(), true}}) {
    const auto estimate = [&](std::size_t threads) {
      const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      return with_gate ? EstimateEgoVelocity(scan, options, gate) : EstimateEgoVelocity(scan, options);
    };
    const EgoVelocityResult one = estimate(1);
    ASSERT_TRUE(one.success) << one.reason;
    EXPECT_LT((one.velocity - sensor).norm(), 0.05);
    for (const std::size_t threads : {2, 8}) {
      const EgoVelocityResult more = estimate(threads);
      EXPECT_EQ(more.velocity, one.velocity) << threads;
      EXPECT_EQ(more.covariance, one.covariance) << threads;
      EXPECT_EQ(more.inlier, one.inlier) << threads;
    }
  }
}

// A radar pitched 1.5 deg down and yawed 0.8 deg right on a vehicle driving a
// straight, a turn and a slow stretch: the straight's velocities give the
// planted angles (turns add the lever arm's lateral velocity: left out of
// the yaw; slow scans are noise: left out), and the levelled track runs
// along x at height 0.
TEST(Mounting, RecoversPlantedPitchAndYawAndLevelsTheTrack) {
  Mounting planted;
  planted.pitch_deg = 1.5;
  planted.yaw_deg = -0.8;
  const SO3d radar_from_vehicle = planted.vehicle_from_radar().Inverse();
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<OdometryStep> steps;
  SE3d vehicle;  // T_vehicle0_vehicle; the world is the first radar frame
  for (int k = 0; k < 300; ++k) {
    const bool turning = k >= 100 && k < 150, slow = k >= 250;
    const double dt = 0.1, speed = slow ? 2.0 : 20.0, yaw_rate = turning ? 0.2 : 0.0;
    Eigen::Vector3d velocity(speed, turning ? 0.8 : 0.0, 0.0);  // vehicle frame; 4 m lever arm when turning
    OdometryStep step;
    step.stamp = dt * k;
    step.velocity_measured = true;
    step.velocity = radar_from_vehicle * velocity + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    vehicle = vehicle * SE3d(SO3d::Exp(Eigen::Vector3d(0.0, 0.0, yaw_rate * dt)), velocity * dt);
    step.pose = SE3d(radar_from_vehicle, Eigen::Vector3d::Zero()) * vehicle *
                SE3d(radar_from_vehicle.Inverse(), Eigen::Vector3d::Zero());  // T_world_radar
    steps.push_back(step);
  }
  const std::optional<Mounting> mounting = EstimateMounting(steps);
  ASSERT_TRUE(mounting.has_value());
  EXPECT_EQ(mounting->pitch_scans, 249u);       // at speed
  EXPECT_EQ(mounting->yaw_scans, 199u);         // the straights at speed
  EXPECT_NEAR(mounting->pitch_deg, 1.5, 0.05);  // 0.14 deg per scan, 199 scans
  EXPECT_NEAR(mounting->yaw_deg, -0.8, 0.05);
  std::vector<StampedPose> poses;
  for (const OdometryStep& step : steps) poses.push_back({step.stamp, step.pose});
  const Trajectory levelled = Levelled(Trajectory(poses), *mounting);
  EXPECT_GT(levelled[99].pose.translation().x(), 190.0);
  EXPECT_NEAR(levelled[99].pose.translation().y(), 0.0, 0.2);
  for (const StampedPose& p : levelled) EXPECT_NEAR(p.pose.translation().z(), 0.0, 0.2) << p.time;
  EXPECT_GT(std::abs(steps[299].pose.translation().z()), 5.0);  // not levelled: the pitch's climb
  steps.resize(10);
  EXPECT_FALSE(EstimateMounting(steps).has_value());  // too few straight scans
  MountingOptions bad;
  bad.min_speed = 0.0;
  EXPECT_THROW(EstimateMounting(steps, bad), std::invalid_argument);
  // By its table's rows, each named: min_scans at least 1, the yaw rate positive and finite.
  for (const auto& [option, set] : std::vector<std::pair<std::string, std::function<void(MountingOptions&)>>>{
           {"min_scans", [](MountingOptions& o) { o.min_scans = 0; }},
           {"max_yaw_rate", [](MountingOptions& o) { o.max_yaw_rate_deg = std::nan(""); }},
           {"min_speed", [](MountingOptions& o) { o.min_speed = -1.0; }}}) {
    MountingOptions o;
    set(o);
    try {
      ValidateOptions(o);
      ADD_FAILURE() << option << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(option), std::string::npos) << e.what();
    }
  }
  ValidateOptions(MountingOptions{});
}

}  // namespace
}  // namespace radargauss
