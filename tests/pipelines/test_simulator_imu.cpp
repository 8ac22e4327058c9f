// SPDX-License-Identifier: BSD-3-Clause
// The simulator's IMU (docs/design/simulator.md, "The synthetic world"): noise-free
// gyro rates integrate to the ground truth's rotations exactly; over a closed lap the
// specific force averages to gravity's reaction; biases and white noise
// follow their laws; the scans are the same with an IMU or without; the
// written files read back.
#include <gtest/gtest.h>

#include <cmath>

#include "radargauss/io/imu.hpp"
#include "radargauss/io/sequence.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

// A small loop, one lap at 6 m/s, an IMU at 1 kHz mounted turned and away
// from the radar, with no noise and no bias unless a test adds them.
SimulationConfig ImuConfig() {
  SimulationConfig config;
  config.loop_length = 40.0;
  config.loop_width = 25.0;
  config.corner_radius = 6.0;
  config.speed = 6.0;
  config.scans = 200;  // 19.9 s: a lap of 2 (40 + 25 - 4 x 6) + 2 pi 6 = 119.7 m takes 19.95 s
  config.min_detections = 20;
  config.max_detections = 40;
  config.poles = 2;
  config.parked_cars = 1;
  config.moving_cars = 0;
  config.mounting_pitch_deg = 1.5;
  config.imu_rate_hz = 1000.0;
  config.imu_roll_deg = 180.0;  // upside down, turned and away from the radar
  config.imu_yaw_deg = 30.0;
  config.imu_x = -1.2;
  config.imu_y = 0.3;
  config.imu_z = 0.4;
  config.imu_noise.gyro_noise_density = config.imu_noise.accel_noise_density = 0.0;
  config.imu_gyro_bias_std = config.imu_accel_bias_std = 0.0;
  config.imu_noise.gyro_bias_random_walk = config.imu_noise.accel_bias_random_walk = 0.0;
  return config;
}

const SimulatedSequence& Clean() {
  static const SimulatedSequence* sequence = new SimulatedSequence(Simulate(ImuConfig()));
  return *sequence;
}

TEST(SimulatedImu, GyroRatesIntegrateToTheTrueRotations) {
  const SimulatedSequence& s = Clean();
  ASSERT_EQ(s.imu.size(), ImuSampleCount(s.config));
  ASSERT_EQ(s.imu.size(), 19901u);  // 19.9 s at 1 kHz, both ends
  const double dt = 1.0 / s.config.imu_rate_hz;
  // From scan k to scan k + 10 (1 s, 1000 samples), each sample held over its
  // interval: the samples are the interval's mean rates, so the product is
  // exact, corners (where the yaw rate steps) included.
  for (std::size_t k = 0; k + 10 < s.scans.size(); k += 10) {
    const std::size_t first = k * 100, last = (k + 10) * 100;
    SO3d integrated;
    for (std::size_t i = first; i < last; ++i) integrated = integrated * SO3d::Exp(s.imu[i].angular_velocity * dt);
    const SO3d truth = (s.ground_truth[k].pose * s.radar_from_imu).rotation().Inverse() *
                       (s.ground_truth[k + 10].pose * s.radar_from_imu).rotation();
    EXPECT_LT((truth.Inverse() * integrated).Log().norm(), 1e-9) << "scan " << k;
  }
}

TEST(SimulatedImu, SpecificForceAveragesToGravitysReactionOverALap) {
  const SimulatedSequence& s = Clean();
  // World-frame specific force R f: over a closed lap at constant speed the
  // acceleration averages out and g's reaction, +9.81 along z, stays.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < s.imu.size(); ++i) {
    const double t = s.imu[i].stamp - s.config.imu_clock_offset;
    const SE3d world_from_imu = *s.ground_truth.Interpolate(std::min(t, s.ground_truth.EndTime())) * s.radar_from_imu;
    mean += world_from_imu.rotation() * s.imu[i].specific_force / double(s.imu.size());
  }
  EXPECT_NEAR(mean.z(), kGravity, 0.05);
  EXPECT_LT(mean.head<2>().norm(), 0.2);
  // Upside down (roll 180 deg): gravity's reaction along the IMU's -z at the start.
  EXPECT_LT(s.imu.front().specific_force.z(), -9.0);
}

TEST(SimulatedImu, BiasesAndNoiseFollowTheirLaws) {
  SimulationConfig biased = ImuConfig();
  biased.imu_gyro_bias_std = 0.01;
  biased.imu_accel_bias_std = 0.1;
  const SimulatedSequence b = Simulate(biased);
  const SimulatedSequence& c = Clean();
  ASSERT_EQ(b.imu.size(), c.imu.size());
  EXPECT_GT(b.imu_bias.front().gyro.norm(), 0.0);
  for (std::size_t i = 0; i < b.imu.size(); i += 97) {  // no walk, no noise: the turn-on bias alone
    EXPECT_LT((b.imu[i].angular_velocity - c.imu[i].angular_velocity - b.imu_bias.front().gyro).norm(), 1e-12);
    EXPECT_LT((b.imu[i].specific_force - c.imu[i].specific_force - b.imu_bias.front().accel).norm(), 1e-9);
  }
  SimulationConfig noisy = biased;
  noisy.imu_noise.gyro_noise_density = 2e-3;
  noisy.imu_noise.gyro_bias_random_walk = 1e-3;
  const SimulatedSequence n = Simulate(noisy);
  const double dt = 1.0 / noisy.imu_rate_hz;
  double noise = 0.0, walk = 0.0;
  for (std::size_t i = 0; i + 1 < n.imu.size(); ++i) {
    noise += (n.imu[i].angular_velocity - c.imu[i].angular_velocity - n.imu_bias[i].gyro).squaredNorm();
    walk += (n.imu_bias[i + 1].gyro - n.imu_bias[i].gyro).squaredNorm();
  }
  const double samples = 3.0 * double(n.imu.size() - 1);
  EXPECT_NEAR(std::sqrt(noise / samples), 2e-3 / std::sqrt(dt), 0.02 * 2e-3 / std::sqrt(dt));
  EXPECT_NEAR(std::sqrt(walk / samples), 1e-3 * std::sqrt(dt), 0.02 * 1e-3 * std::sqrt(dt));
}

TEST(SimulatedImu, ScansAreTheSameWithOrWithoutAnImu) {
  SimulationConfig without = ImuConfig();
  without.imu_rate_hz = 0.0;
  const SimulatedSequence a = Simulate(without);
  const SimulatedSequence& b = Clean();
  EXPECT_TRUE(a.imu.empty());
  ASSERT_EQ(a.scans.size(), b.scans.size());
  for (std::size_t k = 0; k < a.scans.size(); ++k) {
    ASSERT_EQ(a.scans[k].points.size(), b.scans[k].points.size());
    for (std::size_t i = 0; i < a.scans[k].points.size(); ++i) {
      ASSERT_EQ(a.scans[k].points[i].position, b.scans[k].points[i].position);
    }
  }
}

using SimulatedImuFiles = testing::TempDirTest;

TEST_F(SimulatedImuFiles, WrittenFilesReadBackWithTheClockOffset) {
  SimulationConfig config = ImuConfig();
  config.scans = 20;
  config.imu_clock_offset = 0.012;
  const SimulatedSequence s = Simulate(config);
  WriteSimulatedSequence(dir_.string(), s);
  const std::vector<ImuSample> read = ReadImuFile(Path("imu.txt"));
  ASSERT_EQ(read.size(), s.imu.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_NEAR(read[i].stamp, config.start_time + double(i) / config.imu_rate_hz + 0.012, 1e-6);
    EXPECT_EQ(read[i].angular_velocity, s.imu[i].angular_velocity);
    EXPECT_EQ(read[i].specific_force, s.imu[i].specific_force);
  }
  const SE3d extrinsic = ReadExtrinsicFile(Path("imu_extrinsic.txt"));
  EXPECT_LT((extrinsic.translation() - s.radar_from_imu.translation()).norm(), 1e-12);
  EXPECT_LT((extrinsic.rotation().Inverse() * s.radar_from_imu.rotation()).Log().norm(), 1e-12);
  EXPECT_TRUE(std::filesystem::exists(Path("imu_biases.txt")));
}

}  // namespace
}  // namespace radargauss
