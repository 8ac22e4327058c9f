// SPDX-License-Identifier: BSD-3-Clause
// An IMU made from a reference trajectory (docs/design/simulator.md, "An IMU
// from a reference"): the smooth motion through a planted reference sampled
// at 12 Hz gives the planted motion's body rates and specific force, worked
// out by hand from its closed form; what cannot be smoothed is refused.
#include <cmath>

#include <gtest/gtest.h>

#include "radargauss/core/error.hpp"
#include "radargauss/simulator/imu_from_reference.hpp"

namespace radargauss {
namespace {

// A planted drive: x forward at 6 m/s, swaying in y and z; roll, pitch and
// yaw as slow sines on a steady turn. R = Rz(yaw) Ry(pitch) Rx(roll).
struct Planted {
  static Eigen::Vector3d Position(double t) {
    return Eigen::Vector3d(6.0 * t, 3.0 * std::sin(0.4 * t), 0.2 * std::sin(0.3 * t));
  }
  static Eigen::Vector3d Acceleration(double t) {
    return Eigen::Vector3d(0.0, -0.48 * std::sin(0.4 * t), -0.018 * std::sin(0.3 * t));
  }
  static Eigen::Vector3d Angles(double t) {  // roll, pitch, yaw
    return Eigen::Vector3d(0.03 * std::cos(0.4 * t), 0.02 * std::sin(0.5 * t), 0.1 * t + 0.5 * std::sin(0.25 * t));
  }
  static Eigen::Vector3d AngleRates(double t) {
    return Eigen::Vector3d(-0.012 * std::sin(0.4 * t), 0.01 * std::cos(0.5 * t), 0.1 + 0.125 * std::cos(0.25 * t));
  }
  static SO3d Rotation(double t) {
    const Eigen::Vector3d a = Angles(t);
    return SO3d::Exp(Eigen::Vector3d(0.0, 0.0, a(2))) * SO3d::Exp(Eigen::Vector3d(0.0, a(1), 0.0)) *
           SO3d::Exp(Eigen::Vector3d(a(0), 0.0, 0.0));
  }
  // The body rate from the Euler angles' rates (ZYX).
  static Eigen::Vector3d BodyRate(double t) {
    const Eigen::Vector3d a = Angles(t), d = AngleRates(t);
    const double sr = std::sin(a(0)), cr = std::cos(a(0)), sp = std::sin(a(1)), cp = std::cos(a(1));
    return Eigen::Vector3d(d(0) - d(2) * sp, d(1) * cr + d(2) * sr * cp, -d(1) * sr + d(2) * cr * cp);
  }
};

Trajectory PlantedReference(double rate_hz, double duration) {
  Trajectory reference;
  for (int k = 0; k * (1.0 / rate_hz) <= duration; ++k) {
    const double t = k / rate_hz;
    reference.Append(t, SE3d(Planted::Rotation(t), Planted::Position(t)));
  }
  return reference;
}

SimulationConfig NoiseFree() {
  SimulationConfig config;
  config.imu_rate_hz = 200.0;
  config.imu_noise.gyro_noise_density = config.imu_noise.accel_noise_density = 0.0;
  config.imu_gyro_bias_std = config.imu_accel_bias_std = 0.0;
  config.imu_noise.gyro_bias_random_walk = config.imu_noise.accel_bias_random_walk = 0.0;
  config.start_time = 0.0;
  return config;
}

TEST(ImuFromReference, TheSmoothMotionGivesThePlantedRatesAndSpecificForce) {
  const Trajectory reference = PlantedReference(12.0, 30.0);
  const SmoothTrajectory motion(reference, 0.5, 0.0);
  EXPECT_LT(motion.position_rms(), 1e-4);
  EXPECT_LT(motion.rotation_rms(), 0.001 * M_PI / 180.0);
  const SimulationConfig config = NoiseFree();
  const std::size_t count = 30 * 200;
  const SimulatedImu imu = SimulateImuAlong([&](double t) { return motion(t); }, count, config);
  ASSERT_EQ(imu.samples.size(), count);
  // Each sample is its interval's mean: compared at the interval's middle,
  // away from the ends where the spline has poses on one side only.
  double worst_rate = 0.0, worst_force = 0.0;
  for (std::size_t k = 400; k + 400 < count; ++k) {
    const double t = imu.samples[k].stamp + 0.5 / config.imu_rate_hz;
    const Eigen::Vector3d force =
        Planted::Rotation(t).Inverse() * (Planted::Acceleration(t) + Eigen::Vector3d(0.0, 0.0, kGravity));
    worst_rate = std::max(worst_rate, (imu.samples[k].angular_velocity - Planted::BodyRate(t)).norm());
    worst_force = std::max(worst_force, (imu.samples[k].specific_force - force).norm());
  }
  EXPECT_LT(worst_rate, 2e-5);   // rad/s, against rates up to 0.23
  EXPECT_LT(worst_force, 0.01);  // m/s^2, against a lateral 0.48
  // Beyond the reference's ends the motion goes on at its end rate: no jump.
  EXPECT_LT((motion(30.0).translation() - motion(30.0 - 1e-6).translation()).norm(), 1e-4);
  EXPECT_NEAR((motion(31.0).translation() - motion(30.0).translation()).norm(),
              (motion(30.0).translation() - motion(29.99).translation()).norm() * 100.0, 0.05);
}

TEST(ImuFromReference, TheTurnOnBiasIsTheSimulatorsLaw) {
  SimulationConfig config = NoiseFree();
  config.imu_gyro_bias_std = 0.01;
  const SimulatedImu clean =
      SimulateImuAlong([](double t) { return SE3d(SO3d(), Eigen::Vector3d(t, 0, 0)); }, 10, NoiseFree());
  const SimulatedImu biased =
      SimulateImuAlong([](double t) { return SE3d(SO3d(), Eigen::Vector3d(t, 0, 0)); }, 10, config);
  ASSERT_EQ(biased.bias.size(), 10u);
  EXPECT_GT(biased.bias[0].gyro.norm(), 0.0);
  for (std::size_t k = 0; k < 10; ++k) {
    EXPECT_LT((biased.samples[k].angular_velocity - clean.samples[k].angular_velocity - biased.bias[k].gyro).norm(),
              1e-12);
    EXPECT_NEAR(clean.samples[k].specific_force.z(), kGravity, 1e-6);  // at rest but for x: gravity's reaction
  }
}

TEST(ImuFromReference, WhatCannotBeSmoothedIsRefused) {
  EXPECT_THROW(SmoothTrajectory(PlantedReference(12.0, 0.2), 0.5, 0.0), DataError);  // three poses
  EXPECT_THROW(SmoothTrajectory(PlantedReference(12.0, 30.0), 0.0, 0.0), DataError);
  EXPECT_THROW(SmoothTrajectory(PlantedReference(12.0, 30.0), 0.5, -1.0), DataError);
  Trajectory upright;
  for (int k = 0; k < 40; ++k) {
    upright.Append(0.1 * k, SE3d(SO3d::Exp(Eigen::Vector3d(0.0, M_PI / 2.0, 0.0)), Eigen::Vector3d(k, 0, 0)));
  }
  EXPECT_THROW(SmoothTrajectory(upright, 0.5, 0.0), DataError);
}

}  // namespace
}  // namespace radargauss
