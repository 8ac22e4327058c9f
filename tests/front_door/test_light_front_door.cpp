// SPDX-License-Identifier: BSD-3-Clause
// The front door alone: this file includes radargauss/radargauss.hpp and no
// other header of the library, and is built without Ceres on its include
// path (tests/CMakeLists.txt). It simulates a short drive, runs odometry on
// it and evaluates the trajectory, all through the front door.
#include <gtest/gtest.h>

#include <radargauss/radargauss.hpp>

namespace radargauss {
namespace {

TEST(LightFrontDoor, RunsOdometryOnASimulatedDrive) {
  SimulationConfig config;
  config.scans = 30;
  config.seed = 3;
  const SimulatedSequence drive = Simulate(config);
  OdometryOptions options;
  options.initial_pose = drive.ground_truth[0].pose;
  const RadarOdometry odometry = Odometry(AsSequence(drive), options);
  ASSERT_EQ(odometry.steps().size(), drive.scans.size());
  const Evaluation evaluation = EvaluateTrajectory(odometry.trajectory(), drive.ground_truth);
  EXPECT_EQ(evaluation.matched, drive.scans.size());
  EXPECT_LT(evaluation.ate_translation.rmse, 0.3) << "ATE m";
  EXPECT_GT(odometry.map().gaussians(), 50u);
}

}  // namespace
}  // namespace radargauss
