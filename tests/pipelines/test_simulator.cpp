// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/simulator/simulator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "radargauss/core/error.hpp"
#include "radargauss/io/pcd.hpp"
#include "radargauss/io/sequence.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

using SimulatorFiles = testing::TempDirTest;

SimulationConfig SmallConfig() {
  SimulationConfig config;
  config.scans = 40;
  config.seed = 11;
  return config;
}

TEST(Simulator, DeterministicForASeed) {
  const SimulatedSequence a = Simulate(SmallConfig());
  const SimulatedSequence b = Simulate(SmallConfig());
  ASSERT_EQ(a.scans.size(), b.scans.size());
  for (std::size_t k = 0; k < a.scans.size(); ++k) {
    ASSERT_EQ(a.scans[k].points.size(), b.scans[k].points.size());
    for (std::size_t i = 0; i < a.scans[k].points.size(); ++i) {
      ASSERT_EQ(a.scans[k].points[i].position, b.scans[k].points[i].position);
      ASSERT_EQ(a.scans[k].points[i].rcs, b.scans[k].points[i].rcs);
    }
  }
  SimulationConfig other = SmallConfig();
  other.seed = 12;
  EXPECT_NE(Simulate(other).scans[0].points[0].position, a.scans[0].points[0].position);
}

TEST(Simulator, SensorLikeArs548) {
  const SimulatedSequence sequence = Simulate(SmallConfig());
  const SimulationConfig& c = sequence.config;
  std::size_t dynamic = 0, clutter = 0, total = 0;
  for (std::size_t k = 0; k < sequence.scans.size(); ++k) {
    const RadarScan& scan = sequence.scans[k];
    EXPECT_GE(scan.points.size(), 150u);
    EXPECT_LE(scan.points.size(), 800u);
    for (std::size_t i = 0; i < scan.points.size(); ++i) {
      const Eigen::Vector3d& p = scan.points[i].position;
      const double azimuth = std::atan2(p.y(), p.x()) * 180.0 / M_PI;
      const double elevation = std::asin(p.z() / p.norm()) * 180.0 / M_PI;
      EXPECT_LE(std::abs(azimuth), c.azimuth_fov_deg + 2.0);
      EXPECT_LE(std::abs(elevation), c.elevation_fov_deg + 2.0);
      EXPECT_LE(p.norm(), c.max_range + 0.5);
      EXPECT_TRUE(scan.points[i].std_dev.has_value());
      dynamic += sequence.truth[k][i].kind == DetectionKind::kDynamic;
      clutter += sequence.truth[k][i].kind == DetectionKind::kClutter;
      ++total;
    }
  }
  EXPECT_NEAR(double(clutter) / total, c.clutter_fraction, 0.01);
  EXPECT_GT(dynamic, 0u);
  // The drive turns: heading changes by more than 90 degrees over 300 scans
  // (the poses do not depend on the detections, so one per scan is enough).
  SimulationConfig drive;
  drive.min_detections = drive.max_detections = 1;
  const SimulatedSequence full = Simulate(drive);
  ASSERT_EQ(full.ground_truth.size(), 300u);
  const double yaw_first = full.ground_truth[0].pose.rotation().Log().z();
  const Eigen::Matrix3d R_last = full.ground_truth[full.ground_truth.size() - 1].pose.rotation().Matrix();
  EXPECT_GT(std::abs(std::atan2(R_last(1, 0), R_last(0, 0)) - yaw_first), M_PI / 2);
}

// Static points satisfy v_d = -u . v_sensor within the configured noise.
TEST(Simulator, StaticDopplerFollowsEgoVelocity) {
  SimulationConfig config = SmallConfig();
  config.azimuth_noise_deg = 0.0;
  config.elevation_noise_deg = 0.0;
  const SimulatedSequence sequence = Simulate(config);
  double sum = 0.0, sum_sq = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < sequence.scans.size(); ++k) {
    for (std::size_t i = 0; i < sequence.scans[k].points.size(); ++i) {
      if (sequence.truth[k][i].kind != DetectionKind::kStatic) continue;
      const RadarPoint& p = sequence.scans[k].points[i];
      const double residual = p.doppler + p.position.normalized().dot(sequence.sensor_velocity[k]);
      sum += residual;
      sum_sq += residual * residual;
      ++n;
    }
  }
  const double mean = sum / n;
  const double std_dev = std::sqrt(sum_sq / n - mean * mean);
  EXPECT_LT(std::abs(mean), 0.005);
  EXPECT_NEAR(std_dev, config.doppler_noise, 0.1 * config.doppler_noise);
}

// RCS follows the configured incidence law: exactly without noise, with the
// configured spread with noise.
TEST(Simulator, RcsFollowsIncidenceLaw) {
  SimulationConfig config = SmallConfig();
  config.rcs_noise_db = 0.0;
  config.rcs_outlier_fraction = 0.0;
  config.object_rcs_spread_db = 0.0;
  SimulatedSequence sequence = Simulate(config);
  std::size_t checked = 0;
  for (std::size_t k = 0; k < sequence.scans.size(); ++k) {
    for (std::size_t i = 0; i < sequence.scans[k].points.size(); ++i) {
      const DetectionTruth& t = sequence.truth[k][i];
      if (t.kind == DetectionKind::kClutter) continue;
      const double expected = MaterialRcs(config.materials.at(t.material), t.incidence_angle);
      ASSERT_NEAR(sequence.scans[k].points[i].rcs, expected, 1e-9);
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000u);
  // Walls: the specular lobe makes near-normal returns stronger.
  const Material& wall = config.materials.at("wall");
  EXPECT_NEAR(MaterialRcs(wall, 0.0), 10.0 * std::log10(wall.diffuse + wall.specular), 1e-12);
  EXPECT_GT(MaterialRcs(wall, 5.0 * M_PI / 180), MaterialRcs(wall, 45.0 * M_PI / 180) + 5.0);

  config.rcs_noise_db = 1.5;
  sequence = Simulate(config);
  double sum_sq = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < sequence.scans.size(); ++k) {
    for (std::size_t i = 0; i < sequence.scans[k].points.size(); ++i) {
      const DetectionTruth& t = sequence.truth[k][i];
      if (t.kind == DetectionKind::kClutter) continue;
      sum_sq += std::pow(sequence.scans[k].points[i].rcs - t.rcs_noise_free, 2);
      ++n;
    }
  }
  EXPECT_NEAR(std::sqrt(sum_sq / n), 1.5, 0.05);
}

// Written in the Snail-Radar layout, the sequence loads back identically.
TEST_F(SimulatorFiles, RoundTripThroughSnailRadarLoader) {
  SimulationConfig config = SmallConfig();
  config.scans = 15;
  const SimulatedSequence sequence = Simulate(config);
  WriteSimulatedSequence(dir_.string(), sequence);
  SequenceOptions options;
  options.sequence_dir = dir_.string();
  options.ground_truth = Path("gt_radar_tum.txt");
  const Sequence loaded = LoadSequence(options);
  EXPECT_EQ(loaded.layout, "snail-radar");
  ASSERT_EQ(loaded.scans.size(), sequence.scans.size());
  for (std::size_t k = 0; k < loaded.scans.size(); ++k) {
    const RadarScan& a = loaded.scans[k];
    const RadarScan& b = sequence.scans[k];
    EXPECT_EQ(a.timestamp, b.timestamp);
    ASSERT_EQ(a.points.size(), b.points.size());
    for (std::size_t i = 0; i < a.points.size(); ++i) {
      ASSERT_EQ(a.points[i].position, b.points[i].position.cast<float>().cast<double>());
      ASSERT_EQ(a.points[i].doppler, double(float(b.points[i].doppler)));
      ASSERT_EQ(a.points[i].rcs, double(float(b.points[i].rcs)));
      ASSERT_EQ(a.points[i].std_dev->range, b.points[i].std_dev->range);
    }
    EXPECT_LT((loaded.poses[k].Matrix() - sequence.ground_truth[k].pose.Matrix()).norm(), 1e-8);
  }
  // The configuration written beside it reproduces the sequence.
  const SimulationConfig reread = LoadSimulationConfig(Path("simulation.yaml"));
  EXPECT_EQ(SimulationConfigToYaml(reread), SimulationConfigToYaml(config));
}

TEST_F(SimulatorFiles, ConfigFileOverridesAndValidates) {
  const SimulationConfig config =
      LoadSimulationConfig(WriteFile("ok.yaml", "scans: 12\nspeed: 3.5\nmaterials:\n  wall: {specular: 8.0}\n"));
  EXPECT_EQ(config.scans, 12);
  EXPECT_EQ(config.speed, 3.5);
  EXPECT_EQ(config.materials.at("wall").specular, 8.0);
  EXPECT_EQ(config.materials.at("wall").diffuse, SimulationConfig{}.materials.at("wall").diffuse);
  const auto expect_error = [&](const std::string& text, const std::string& fault) {
    const std::string path = WriteFile("bad.yaml", text);
    try {
      LoadSimulationConfig(path);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const DataError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(fault), std::string::npos) << e.what();
    }
  };
  expect_error("scanz: 3\n", "unknown parameter 'scanz'");
  expect_error("scans: many\n", "wrong type");
  expect_error("scans: 0\n", "scans = 0 is not in [1, ");
  expect_error("seed: -1\n", "seed = -1 is not in [0, 4294967295]");
  expect_error("max_detections: 100\n", "max_detections (100) must be at least min_detections (150)");
  expect_error("min_detections: 900\n", "min_detections");
  expect_error("materials: {glass: {diffuse: 1}}\n", "unknown material");
  expect_error("scans: [1, 2\n", "YAML");
  EXPECT_THROW(LoadSimulationConfig(Path("absent.yaml")), DataError);
}

// Every number of the configuration is bounded: 1e300 and -1e300 in any key
// are refused naming that key, and the largest accepted magnitudes (noise
// growth, traffic and ego speeds, noise) still simulate scans that the
// readers accept (Simulate validates every scan it returns).
TEST_F(SimulatorFiles, EveryNumberIsBoundedAndTheBoundsSimulate) {
  std::istringstream defaults(SimulationConfigToYaml(SimulationConfig{}));
  std::size_t keys = 0;
  for (std::string line; std::getline(defaults, line) && line != "materials:";) {
    const std::string key = line.substr(0, line.find(':'));
    if (key == "scene") continue;
    for (const char* huge : {"1e300", "-1e300"}) {
      const std::string path = WriteFile("huge.yaml", key + ": " + huge + "\n");
      try {
        LoadSimulationConfig(path);
        ADD_FAILURE() << key << ": " << huge << " accepted";
      } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
      }
    }
    ++keys;
  }
  EXPECT_GT(keys, 40u);
  SimulationConfig config;
  config.scene = "motorway";
  config.scans = 3;
  config.elevation_noise_growth = 100.0;
  config.traffic_min_speed = config.traffic_max_speed = 150.0;
  config.speed = 150.0;
  config.doppler_noise = config.range_noise = 100.0;
  config.rcs_noise_db = 200.0;
  config.imu_rate_hz = 2000.0;
  config.imu_noise.gyro_noise_density = config.imu_noise.gyro_bias_random_walk = 0.1;
  config.imu_noise.accel_noise_density = config.imu_noise.accel_bias_random_walk = 1.0;
  config.imu_gyro_bias_std = 1.0;
  config.imu_accel_bias_std = 10.0;
  config.imu_x = config.imu_y = config.imu_z = 10.0;
  config.imu_clock_offset = 0.5;
  const SimulatedSequence sequence = Simulate(config);
  ASSERT_EQ(sequence.scans.size(), 3u);
  for (const RadarScan& scan : sequence.scans) EXPECT_NO_THROW(ValidateScan(scan, "scan"));
  ASSERT_EQ(sequence.imu.size(), 401u);
  for (const ImuSample& sample : sequence.imu) {
    EXPECT_TRUE(std::isfinite(sample.stamp) && sample.angular_velocity.allFinite() &&
                sample.specific_force.allFinite());
  }
}

TEST(Simulator, TimestampStems) {
  EXPECT_EQ(TimestampStem(1702450000.25), "1702450000.250000000");
  SimulationConfig config = SmallConfig();
  config.scans = 3;
  const SimulatedSequence sequence = Simulate(config);
  EXPECT_EQ(sequence.file_stems[1], "1702450000.100000000");
  double parsed = 0.0;
  ASSERT_TRUE(TimestampFromFileName(sequence.file_stems[2] + ".pcd", parsed));
  EXPECT_EQ(parsed, sequence.scans[2].timestamp);
  EXPECT_EQ(TimestampStem(0.083221619), "0.083221619");
  EXPECT_EQ(TimestampStem(4.9999999999), "5.000000000");
}

}  // namespace
}  // namespace radargauss

namespace radargauss {
namespace {

// The documented parameter file lists exactly the built-in defaults.
TEST(SimulatorConfigFile, DocumentedDefaultsMatchCode) {
  const SimulationConfig documented =
      LoadSimulationConfig(std::string(RADARGAUSS_SOURCE_DIR) + "/configs/synthetic_world.yaml");
  EXPECT_EQ(SimulationConfigToYaml(documented), SimulationConfigToYaml(SimulationConfig{}));
}

}  // namespace
}  // namespace radargauss
