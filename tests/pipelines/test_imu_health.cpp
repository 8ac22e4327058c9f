// SPDX-License-Identifier: BSD-3-Clause
// The IMU checked against the radar (docs/design/odometry.md, "The IMU's
// health"): on a simulated drive with a MEMS IMU, each planted fault is
// caught with its cause, and the run is then the radar alone's. The
// healthy IMU passes, and its trajectory is the one without the check.
#include <functional>

#include <gtest/gtest.h>

#include "radargauss/experiment/evaluation.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "support/inertial_drive.hpp"

namespace radargauss {
namespace {

// 30 s of the demo world (two corners), an IMU at 200 Hz.
const SimulatedSequence& Drive() { return testing::DemoDriveWithImu(300); }

struct Outcome {
  double rpe = 0.0;
  std::optional<ImuFault> fault;
  std::vector<OdometryStep> steps;
};

Outcome Odometry(std::vector<ImuSample> imu, const SE3d& radar_from_imu, bool check = true) {
  const Sequence sequence = AsSequence(Drive());
  RadarInertialOptions options;
  options.health_check = check;
  RadarOdometry odometry(OdometryOptions{},
                         imu.empty() ? nullptr : std::make_unique<InertialMotion>(options, radar_from_imu, imu));
  for (const RadarScan& scan : sequence.scans) odometry.Register(scan);
  Outcome run;
  run.rpe = EvaluateTrajectory(odometry.trajectory(), Drive().ground_truth).rpe_mean.translation;
  if (const InertialMotion* inertial = InertialMotionOf(odometry)) run.fault = inertial->imu_fault();
  run.steps = odometry.steps();
  return run;
}

std::vector<ImuSample> Planted(const std::function<void(ImuSample&)>& fault) {
  std::vector<ImuSample> imu = Drive().imu;
  for (ImuSample& sample : imu) fault(sample);
  return imu;
}

TEST(ImuHealth, AHealthyImuPassesAndTheCheckChangesNothing) {
  const Outcome checked = Odometry(Drive().imu, Drive().radar_from_imu);
  EXPECT_FALSE(checked.fault) << checked.fault->cause;
  const Outcome unchecked = Odometry(Drive().imu, Drive().radar_from_imu, false);
  ASSERT_EQ(checked.steps.size(), unchecked.steps.size());
  for (std::size_t k = 0; k < checked.steps.size(); ++k) {
    ASSERT_EQ(checked.steps[k].pose.translation(), unchecked.steps[k].pose.translation()) << "scan " << k;
  }
}

// Each planted fault is caught with its cause: the accelerometer's before
// the first scan, the gyro's on the first corner, the clock's once the
// turns show the lag. Until then the radar alone ran beside the window, and
// the run goes on as it: the trajectory is the radar alone's, scan for scan.
TEST(ImuHealth, EachPlantedFaultIsCaughtAndTheRunIsTheRadarAlones) {
  const Outcome radar = Odometry({}, SE3d());
  const SE3d truth = Drive().radar_from_imu;
  const SE3d tilted = truth * SE3d(SO3d::Exp(Eigen::Vector3d(20.0 * M_PI / 180.0, 0.0, 0.0)), Eigen::Vector3d::Zero());
  struct Case {
    std::string name, cause;
    std::vector<ImuSample> imu;
    SE3d radar_from_imu;
  };
  const std::vector<Case> cases = {
      {"gyro x and z swapped", "axes",
       Planted([](ImuSample& s) { std::swap(s.angular_velocity.x(), s.angular_velocity.z()); }), truth},
      {"accelerometer in g", "in g", Planted([](ImuSample& s) { s.specific_force /= kGravity; }), truth},
      {"accelerometer negated", "sign", Planted([](ImuSample& s) { s.specific_force = -s.specific_force; }), truth},
      {"extrinsic 20 deg off", "extrinsic", Drive().imu, tilted},
      {"clock 0.3 s off", "clock", Planted([](ImuSample& s) { s.stamp += 0.3; }), truth},
      {"clock 1 s off", "clock", Planted([](ImuSample& s) { s.stamp += 1.0; }), truth},
  };
  for (const Case& c : cases) {
    const Outcome run = Odometry(c.imu, c.radar_from_imu);
    ASSERT_TRUE(run.fault) << c.name << ": not caught";
    EXPECT_NE(run.fault->cause.find(c.cause), std::string::npos) << c.name << ": " << run.fault->cause;
    ASSERT_EQ(run.steps.size(), radar.steps.size());
    for (std::size_t k = 0; k < run.steps.size(); ++k) {
      ASSERT_EQ(run.steps[k].pose.translation(), radar.steps[k].pose.translation()) << c.name << ", scan " << k;
    }
    EXPECT_EQ(run.rpe, radar.rpe) << c.name;
  }
}

}  // namespace
}  // namespace radargauss
