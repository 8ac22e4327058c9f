// SPDX-License-Identifier: BSD-3-Clause
// The simulator's faults of real radars (docs/design/simulator.md, "The faults of real
// radars"), each against its law: ghosts mirrored across their reflector
// with the mirrored Doppler, Swerling RCS variances, the elevation bias and
// its growth off boresight, the mounting offset, the motorway's traffic, and
// determinism with every fault on; and the odometry's counter-measures: the
// elevation bias removed and estimated, the mounting given.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "radargauss/core/error.hpp"
#include "radargauss/experiment/evaluation.hpp"
#include "radargauss/io/sequence.hpp"
#include "radargauss/odometry/elevation_bias.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Noise-free measurements, no clutter or outliers: each law shows exactly.
SimulationConfig Exact(int scans) {
  SimulationConfig config;
  config.scans = scans;
  config.seed = 5;
  config.range_noise = config.azimuth_noise_deg = config.elevation_noise_deg = 0.0;
  config.doppler_noise = config.rcs_noise_db = 0.0;
  config.clutter_fraction = config.rcs_outlier_fraction = 0.0;
  return config;
}

Eigen::Vector3d Mirror(const Eigen::Vector3d& v, const Eigen::Vector3d& n) { return v - 2.0 * v.dot(n) * n; }

SimulationConfig Motorway(SimulationConfig config) {
  config.scene = "motorway";
  config.loop_length = 3000.0;
  config.loop_width = 300.0;
  config.corner_radius = 140.0;
  config.speed = 34.0;
  config.moving_cars = 40;
  return config;
}

// On the motorway, whose guardrails run beside the traffic.
TEST(RadarFaults, GhostsLieMirroredAcrossTheirReflectorWithTheMirroredDoppler) {
  SimulationConfig config = Motorway(Exact(30));
  config.multipath_probability = 1.0;
  const SimulatedSequence run = Simulate(config);
  std::size_t ghosts = 0, moving = 0, moving_doppler = 0;
  for (std::size_t k = 0; k < run.scans.size(); ++k) {
    const SE3d pose = run.ground_truth[k].pose;
    const Eigen::Vector3d sensor_velocity = pose.rotation() * run.sensor_velocity[k];
    for (std::size_t i = 0; i < run.scans[k].points.size(); ++i) {
      const DetectionTruth& truth = run.truth[k][i];
      if (truth.kind != DetectionKind::kGhost) continue;
      ++ghosts;
      const Eigen::Vector3d& n = truth.reflector_normal;
      const Eigen::Vector3d image = truth.reflector_point + Mirror(truth.position_world - truth.reflector_point, n);
      const Eigen::Vector3d seen = pose * run.scans[k].points[i].position;
      ASSERT_LT((seen - image).norm(), 1e-6) << "scan " << k;
      EXPECT_LT((seen - truth.reflector_point).dot(n), 0.0);  // behind the reflector
      EXPECT_GT((pose.translation() - truth.reflector_point).dot(n), 0.0);
      const Eigen::Vector3d u = (seen - pose.translation()).normalized();
      const double mirrored = u.dot(Mirror(truth.target_velocity, n) - sensor_velocity);
      EXPECT_NEAR(run.scans[k].points[i].doppler, mirrored, 1e-6);
      if (truth.target_velocity.norm() > 0.0) {
        ++moving;
        moving_doppler += std::abs(mirrored - u.dot(-sensor_velocity)) > 0.5;  // not a static point's
      }
    }
  }
  EXPECT_GT(ghosts, 100u);
  EXPECT_GT(moving, 0u);
  EXPECT_GT(moving_doppler, moving / 2);  // a car's ghost moves: Doppler filters can reject it
}

// Swerling I: exponential power, variance 1 (mean 1); Swerling III:
// chi-square of 4 degrees of freedom, variance 1/2.
TEST(RadarFaults, FluctuatingRcsHasTheLawsVariance) {
  for (const int law : {0, 1, 3}) {
    SimulationConfig config = Exact(60);
    config.rcs_swerling = law;
    const SimulatedSequence run = Simulate(config);
    double sum = 0.0, squares = 0.0;
    std::size_t n = 0;
    for (std::size_t k = 0; k < run.scans.size(); ++k) {
      for (std::size_t i = 0; i < run.scans[k].points.size(); ++i) {
        const double power = std::pow(10.0, (run.scans[k].points[i].rcs - run.truth[k][i].rcs_noise_free) / 10.0);
        sum += power;
        squares += power * power;
        ++n;
      }
    }
    const double mean = sum / double(n), variance = squares / double(n) - mean * mean;
    const double expected = law == 0 ? 0.0 : law == 1 ? 1.0 : 0.5;
    EXPECT_NEAR(mean, 1.0, law == 0 ? 1e-12 : 0.03) << "Swerling " << law << " over " << n;
    EXPECT_NEAR(variance, expected, law == 0 ? 1e-12 : 0.08 * expected) << "Swerling " << law;
  }
}

double Elevation(const Eigen::Vector3d& p) { return std::atan2(p.z(), p.head<2>().norm()); }

// The same rays with and without a 1 deg bias (the bias draws nothing): every
// elevation moves by it, range and azimuth stay; the reported elevation std
// grows off boresight as (1 + growth (azimuth / fov)^2).
TEST(RadarFaults, ElevationBiasShiftsEveryElevationAndNoiseGrowsOffBoresight) {
  const SimulationConfig exact = Exact(10);
  SimulationConfig biased = exact;
  biased.elevation_bias_deg = 1.0;
  const SimulatedSequence a = Simulate(exact), b = Simulate(biased);
  for (std::size_t k = 0; k < a.scans.size(); ++k) {
    ASSERT_EQ(a.scans[k].points.size(), b.scans[k].points.size());
    for (std::size_t i = 0; i < a.scans[k].points.size(); ++i) {
      const Eigen::Vector3d &p = a.scans[k].points[i].position, &q = b.scans[k].points[i].position;
      ASSERT_NEAR(Elevation(q) - Elevation(p), 1.0 * kDeg, 1e-9);
      ASSERT_NEAR(q.norm(), p.norm(), 1e-9);
      ASSERT_NEAR(std::atan2(q.y(), q.x()), std::atan2(p.y(), p.x()), 1e-9);
    }
  }
  SimulationConfig growing = SimulationConfig();
  growing.scans = 3;
  growing.elevation_noise_growth = 2.0;
  const SimulatedSequence c = Simulate(growing);
  for (std::size_t i = 0; i < c.scans[0].points.size(); ++i) {
    if (c.truth[0][i].kind == DetectionKind::kClutter) continue;
    const Eigen::Vector3d& p = c.scans[0].points[i].position;
    const double fraction = std::atan2(p.y(), p.x()) / (growing.azimuth_fov_deg * kDeg);  // measured azimuth
    const double expected = growing.elevation_noise_deg * kDeg * (1.0 + 2.0 * fraction * fraction);
    EXPECT_NEAR(c.scans[0].points[i].std_dev->elevation, expected, 2e-4) << i;  // azimuth noise 0.2 deg
  }
}

// The radar mounted rolled, pitched and yawed: the true radar pose is the
// vehicle's times the mounting, and its velocity turns with it.
TEST(RadarFaults, MountingOffsetRotatesTheSensorFrameByIt) {
  const SimulationConfig level = Exact(20);
  SimulationConfig mounted = level;
  mounted.mounting_roll_deg = 1.0;
  mounted.mounting_pitch_deg = 2.0;
  mounted.mounting_yaw_deg = -3.0;
  const SO3d mounting = SO3d::Exp(Eigen::Vector3d(0.0, 0.0, -3.0 * kDeg)) *
                        SO3d::Exp(Eigen::Vector3d(0.0, 2.0 * kDeg, 0.0)) *
                        SO3d::Exp(Eigen::Vector3d(1.0 * kDeg, 0.0, 0.0));
  const SimulatedSequence a = Simulate(level), b = Simulate(mounted);
  for (std::size_t k = 0; k < a.scans.size(); ++k) {
    const SE3d offset = a.ground_truth[k].pose.Inverse() * b.ground_truth[k].pose;
    EXPECT_LT(offset.translation().norm(), 1e-12);
    EXPECT_LT((offset.rotation().Inverse() * mounting).Log().norm(), 1e-12) << k;
    EXPECT_LT((b.sensor_velocity[k] - mounting.Inverse() * a.sensor_velocity[k]).norm(), 1e-9) << k;
  }
}

// The motorway: guardrails seen, traffic both ways at 25-40 m/s.
TEST(RadarFaults, MotorwayHasGuardrailsAndTrafficBothWays) {
  SimulationConfig config = Motorway(SimulationConfig());
  config.scans = 40;
  const SimulatedSequence run = Simulate(config);
  std::size_t guardrail = 0, with = 0, against = 0;
  for (std::size_t k = 0; k < run.scans.size(); ++k) {
    const Eigen::Vector3d forward = run.ground_truth[k].pose.rotation() * Eigen::Vector3d::UnitX();
    for (const DetectionTruth& truth : run.truth[k]) {
      guardrail += truth.material == "guardrail";
      if (truth.kind != DetectionKind::kDynamic) continue;
      EXPECT_GE(truth.target_velocity.norm(), 25.0 - 1e-9);
      EXPECT_LE(truth.target_velocity.norm(), 40.0 + 1e-9);
      (truth.target_velocity.dot(forward) > 0.0 ? with : against) += 1;
    }
  }
  EXPECT_GT(guardrail, 1000u);
  EXPECT_GT(with, 0u);
  EXPECT_GT(against, 0u);
}

TEST(RadarFaults, DeterministicWithEveryFaultOn) {
  SimulationConfig config;
  config.scans = 15;
  config.elevation_bias_deg = 0.5;
  config.elevation_noise_growth = 1.0;
  config.mounting_pitch_deg = 1.5;
  config.rcs_swerling = 3;
  config.multipath_probability = 0.3;
  const SimulatedSequence a = Simulate(config), b = Simulate(config);
  for (std::size_t k = 0; k < a.scans.size(); ++k) {
    ASSERT_EQ(a.scans[k].points.size(), b.scans[k].points.size());
    for (std::size_t i = 0; i < a.scans[k].points.size(); ++i) {
      ASSERT_EQ(a.scans[k].points[i].position, b.scans[k].points[i].position);
      ASSERT_EQ(a.scans[k].points[i].doppler, b.scans[k].points[i].doppler);
      ASSERT_EQ(a.scans[k].points[i].rcs, b.scans[k].points[i].rcs);
      ASSERT_EQ(a.truth[k][i].kind, b.truth[k][i].kind);
    }
  }
  config.seed = 2;
  EXPECT_NE(Simulate(config).scans[0].points[0].position, a.scans[0].points[0].position);
}

// The biased run's points, lowered by the bias, are the unbiased run's.
TEST(ElevationBias, CorrectionUndoesTheBias) {
  SimulationConfig biased = Exact(3);
  biased.elevation_bias_deg = 1.0;
  const SimulatedSequence a = Simulate(Exact(3)), b = Simulate(biased);
  for (std::size_t k = 0; k < a.scans.size(); ++k) {
    RadarScan corrected = b.scans[k];
    LowerElevations(corrected, 1.0 * kDeg);
    for (std::size_t i = 0; i < a.scans[k].points.size(); ++i) {
      ASSERT_LT((corrected.points[i].position - a.scans[k].points[i].position).norm(), 1e-9);
    }
  }
  ElevationBiasOptions options;
  options.window = 0;
  EXPECT_THROW(ElevationBias(options, SO3d()), std::invalid_argument);
}

// Read with the bias given (every command's --elevation-bias), the biased
// run's files give the unbiased run's points (float32 files: 1e-4 m).
using ElevationBiasFiles = testing::TempDirTest;
TEST_F(ElevationBiasFiles, ReadingRemovesAGivenBias) {
  SimulationConfig biased = Exact(3);
  biased.elevation_bias_deg = 1.0;
  const SimulatedSequence a = Simulate(Exact(3));
  WriteSimulatedSequence(Path("biased"), Simulate(biased));
  SequenceOptions options;
  options.sequence_dir = Path("biased");
  options.elevation_bias_deg = 1.0;
  const Sequence read = LoadSequence(options);
  ASSERT_EQ(read.scans.size(), a.scans.size());
  for (std::size_t k = 0; k < a.scans.size(); ++k) {
    for (std::size_t i = 0; i < a.scans[k].points.size(); ++i) {
      ASSERT_LT((read.scans[k].points[i].position - a.scans[k].points[i].position).norm(), 1e-4);
    }
  }
  options.elevation_bias_deg = 50.0;
  EXPECT_THROW(LoadSequence(options), DataError);
}

double OdometryRpe(const SimulatedSequence& run, const OdometryOptions& options, double* bias = nullptr) {
  RadarOdometry odometry(options);
  for (const RadarScan& scan : run.scans) odometry.Register(scan);
  if (bias != nullptr) *bias = odometry.elevation_bias_deg();
  return EvaluateTrajectory(odometry.trajectory(), run.ground_truth).rpe_mean.translation;
}

// On the demo's drive (bench/REAL_RADAR.md, fault table): a 1 deg elevation
// bias costs 0.38 points of RPE as is; estimated from the Doppler velocity
// it is found within 0.15 deg and costs under 0.1. A radar mounted 1.5 deg
// down (0.5 roll, -1 yaw) costs 0.35 points unless the mounting is given.
TEST(OdometryCounterMeasures, EstimatedBiasAndGivenMountingRecoverTheCleanDrift) {
  SimulationConfig config;
  const double clean = OdometryRpe(Simulate(config), OdometryOptions());
  config.elevation_bias_deg = 1.0;
  const SimulatedSequence biased = Simulate(config);
  OdometryOptions estimating;
  estimating.elevation_bias.estimate = true;
  double estimate = 0.0;
  const double corrected = OdometryRpe(biased, estimating, &estimate);
  EXPECT_GT(OdometryRpe(biased, OdometryOptions()), clean + 0.25);
  EXPECT_LT(corrected, clean + 0.1);
  EXPECT_NEAR(estimate, 1.0, 0.15);
  config.elevation_bias_deg = 0.0;
  config.mounting_roll_deg = 0.5;
  config.mounting_pitch_deg = 1.5;
  config.mounting_yaw_deg = -1.0;
  const SimulatedSequence mounted = Simulate(config);
  OdometryOptions given;
  given.mounting_deg = Eigen::Vector3d(0.5, 1.5, -1.0);
  EXPECT_GT(OdometryRpe(mounted, OdometryOptions()), clean + 0.25);
  EXPECT_LT(OdometryRpe(mounted, given), clean + 0.1);
}

}  // namespace
}  // namespace radargauss
