// SPDX-License-Identifier: BSD-3-Clause
// The IMU checked against the radar (docs/design/odometry.md, "The IMU's
// health"): on a simulated drive with a MEMS IMU, each planted fault is
// caught with its cause; the accelerometer's and the clock's at no cost
// against the radar alone. The healthy IMU passes, and its trajectory is
// the one without the check.
#include <functional>

#include <gtest/gtest.h>

#include "radargauss/experiment/evaluation.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/simulator/simulator.hpp"

namespace radargauss {
namespace {

// 30 s of the demo world (two corners), an IMU at 200 Hz.
const SimulatedSequence& Drive() {
  static const SimulatedSequence* sequence = [] {
    SimulationConfig config;
    config.scans = 300;
    config.imu_rate_hz = 200.0;
    return new SimulatedSequence(Simulate(config));
  }();
  return *sequence;
}

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

// The accelerometer's faults are found before the first scan (the run is
// the radar's alone), the clock's once the turns show the lag (10 s of
// scans); each run is within 10 % of the radar alone's drift but the one
// whose clock is 1 s off, which the window fused until then.
TEST(ImuHealth, AccelerometerAndClockFaultsAreCaughtAndCostNothing) {
  const double radar = Odometry({}, SE3d()).rpe;
  struct Case {
    std::string name, cause;
    std::vector<ImuSample> imu;
    bool costs_nothing = true;
  };
  const std::vector<Case> cases = {
      {"accelerometer in g", "in g", Planted([](ImuSample& s) { s.specific_force /= kGravity; })},
      {"accelerometer negated", "sign", Planted([](ImuSample& s) { s.specific_force = -s.specific_force; })},
      {"clock 0.3 s off", "clock", Planted([](ImuSample& s) { s.stamp += 0.3; })},
      {"clock 1 s off", "clock", Planted([](ImuSample& s) { s.stamp += 1.0; }), false},
  };
  for (const Case& c : cases) {
    const Outcome run = Odometry(c.imu, Drive().radar_from_imu);
    ASSERT_TRUE(run.fault) << c.name << ": not caught";
    EXPECT_NE(run.fault->cause.find(c.cause), std::string::npos) << c.name << ": " << run.fault->cause;
    if (c.costs_nothing)
      EXPECT_LT(run.rpe, 1.1 * radar) << c.name << ": " << run.rpe << " % against the radar's " << radar << " %";
  }
}

// The gyro's x and z swapped: found on the first corner, by the axis of
// its turn against the radar's (the window has fused it until then).
TEST(ImuHealth, SwappedGyroAxesAreCaughtOnTheFirstTurn) {
  const Outcome run = Odometry(Planted([](ImuSample& s) { std::swap(s.angular_velocity.x(), s.angular_velocity.z()); }),
                               Drive().radar_from_imu);
  ASSERT_TRUE(run.fault);
  EXPECT_NE(run.fault->cause.find("axes"), std::string::npos) << run.fault->cause;
  EXPECT_LT(run.fault->stamp, Drive().imu.front().stamp + 20.0);
}

}  // namespace
}  // namespace radargauss
