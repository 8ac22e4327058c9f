// SPDX-License-Identifier: BSD-3-Clause
// IMU files (io/imu.hpp): planted samples read back exactly, every malformed
// line refused naming its line, the summary's rate, gaps and means against a
// planted file, the extrinsic file, and the noise options' table.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "radargauss/core/error.hpp"
#include "radargauss/io/imu.hpp"
#include "radargauss/io/sequence.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

using ImuFile = testing::TempDirTest;

std::string Refusal(const std::string& path) {
  try {
    ReadImuFile(path);
  } catch (const DataError& e) {
    return e.what();
  }
  return "accepted";
}

TEST_F(ImuFile, ReadsPlantedSamplesWithCommentsAndBlankLines) {
  const std::string path = WriteFile("imu.txt",
                                     "# stamp wx wy wz ax ay az\n\n"
                                     "10.000 0.1 -0.2 0.3 1.5 -2.5 9.75\r\n"
                                     "  10.005\t0 0 0.25 0 0 9.81  # not a comment: refused below\n");
  EXPECT_EQ(Refusal(path), path + ":4: not a number: '#'");
  WriteFile("imu.txt",
            "# stamp wx wy wz ax ay az\n\n10.000 0.1 -0.2 0.3 1.5 -2.5 9.75\r\n  10.005\t0 0 0.25 0 0 9.81\n");
  const std::vector<ImuSample> samples = ReadImuFile(path);
  ASSERT_EQ(samples.size(), 2u);
  EXPECT_EQ(samples[0].stamp, 10.0);
  EXPECT_EQ(samples[0].angular_velocity, Eigen::Vector3d(0.1, -0.2, 0.3));
  EXPECT_EQ(samples[0].specific_force, Eigen::Vector3d(1.5, -2.5, 9.75));
  EXPECT_EQ(samples[1].stamp, 10.005);
  EXPECT_EQ(samples[1].angular_velocity.z(), 0.25);
}

TEST_F(ImuFile, RefusesEachMalformedLineNamingIt) {
  const std::string good = "1 0 0 0 0 0 9.8\n";
  const std::pair<std::string, std::string> cases[] = {
      {good + "1 0 0 0 0 0 9.8\n", ":2: stamp does not increase"},
      {good + "0.5 0 0 0 0 0 9.8\n", ":2: stamp does not increase"},
      {good + "2 0 nan 0 0 0 9.8\n", ":2: non-finite value"},
      {good + "2 0 0 0 0 0 inf\n", ":2: non-finite value"},
      {good + "2 0 0 0 0", ":2: expected 7 columns (stamp wx wy wz ax ay az), found 5"},
      {good + "2 0 0 0 0 0 9.8 1\n", ":2: expected 7 columns (stamp wx wy wz ax ay az), found 8"},
      {good + "2 0 0 0x 0 0 9.8\n", ":2: not a number: '0x'"},
      {good + "2 1e300 0 0 0 0 9.8\n", ":2: angular rate 1e+300 rad/s is past any IMU's 10000"},
      {good + "2 0 0 0 0 0 -2e5\n", ":2: specific force 200000 m/s^2 is past any IMU's 100000"},
      {"# only a comment\n", ": no IMU sample (lines 'stamp wx wy wz ax ay az')"},
  };
  for (const auto& [content, message] : cases) {
    const std::string path = WriteFile("bad.txt", content);
    EXPECT_EQ(Refusal(path), path + message) << content;
  }
  EXPECT_NE(Refusal(Path("absent.txt")).find("absent.txt"), std::string::npos);
}

TEST_F(ImuFile, SummaryStatesRateGapsAndMeans) {
  // 100 Hz for 2 s with one 50 ms gap; the rates and forces alternate about planted means.
  std::string content;
  double stamp = 5.0;
  for (int k = 0; k < 200; ++k) {
    const double sign = k % 2 == 0 ? 1.0 : -1.0;
    char line[160];
    std::snprintf(line, sizeof(line), "%.6f %.6f 0 0.02 %.6f 0.3 9.81\n", stamp, 0.01 * sign, 0.2 + 0.1 * sign);
    content += line;
    stamp += k == 100 ? 0.05 : 0.01;
  }
  const ImuSummary s = SummariseImu(ReadImuFile(WriteFile("imu.txt", content)));
  EXPECT_EQ(s.samples, 200u);
  EXPECT_DOUBLE_EQ(s.start, 5.0);
  EXPECT_NEAR(s.end, 5.0 + 198 * 0.01 + 0.05, 1e-9);
  EXPECT_NEAR(s.rate_hz, 100.0, 1e-3);
  EXPECT_EQ(s.gaps, 1u);
  EXPECT_NEAR(s.max_gap, 0.05, 1e-9);
  EXPECT_TRUE(s.mean_angular_velocity.isApprox(Eigen::Vector3d(0.0, 0.0, 0.02), 1e-9));
  EXPECT_TRUE(s.mean_specific_force.isApprox(Eigen::Vector3d(0.2, 0.3, 9.81), 1e-9));
  EXPECT_THROW(SummariseImu({}), std::invalid_argument);
}

TEST_F(ImuFile, ExtrinsicFileIsAPose) {
  const std::string path =
      WriteFile("T_radar_imu.txt", "# x y z qx qy qz qw\n0.1 -0.2 0.3 0 0 0.7071067811865476 0.7071067811865476\n");
  const SE3d T = ReadExtrinsicFile(path);
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(0.1, -0.2, 0.3)));
  EXPECT_TRUE((T.rotation() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  WriteFile("T_radar_imu.txt", "0 0 0 0 0 0 2\n");
  EXPECT_THROW(ReadExtrinsicFile(path), DataError);
  const auto refusal = [&](const std::string& content) {
    WriteFile("T_radar_imu.txt", content);
    try {
      ReadExtrinsicFile(path);
    } catch (const DataError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refusal("0 0 nan 0 0 0 1\n"), path + ": extrinsic holds nan, a value that is not finite");
  EXPECT_EQ(refusal("0 0 1e400 0 0 0 1\n"), path + ": extrinsic holds 1e400, a value that is not finite");
  EXPECT_EQ(refusal("0 0 x 0 0 0 1\n"), path + ": extrinsic holds 'x', not a number");
  EXPECT_EQ(refusal("1e300 0 0 0 0 0 1\n"),
            path + ": extrinsic's translation is past 1000 m (a sensor's mounting on its vehicle)");
  EXPECT_EQ(refusal("0 0 0 0 0 0 1 0\n"), path + ": extrinsic needs exactly 7 numbers");
  // A stated accuracy: read when there, none when not; out of its ranges refused.
  WriteFile("T_radar_imu.txt", "0 0 0 0 0 0 1\n# rough\nstd 2 0.05 0.02\n");
  const StatedExtrinsic rough = ReadStatedExtrinsicFile(path);
  ASSERT_TRUE(rough.accuracy.has_value());
  EXPECT_EQ(rough.accuracy->rotation_deg, 2.0);
  EXPECT_EQ(rough.accuracy->translation, 0.05);
  EXPECT_EQ(rough.accuracy->clock_offset, 0.02);
  WriteFile("T_radar_imu.txt", "0 0 0 0 0 0 1\n");
  EXPECT_FALSE(ReadStatedExtrinsicFile(path).accuracy.has_value());
  EXPECT_EQ(refusal("0 0 0 0 0 0 1\nstd 2 0.05\n"),
            path + ": extrinsic needs 'std <rotation deg> <translation m> <clock offset s>'");
  EXPECT_EQ(refusal("0 0 0 0 0 0 1\nstd -1 0 0\n"),
            path + ": extrinsic's stds must be 0 to 180 deg, 0 to 1000 m and 0 to 1 s");
  EXPECT_EQ(refusal("0 0 0 0 0 0 1\nstd 1 0 0\nstd 1 0 0\n"), path + ": extrinsic states its accuracy twice");
}

// A drive's samples with one glitched sample on each sensor and two beyond
// the range: exactly those are dropped, and counted.
TEST(ImuScreening, DropsPlantedSpikesAndSamplesBeyondTheRange) {
  std::vector<ImuSample> samples;
  for (int k = 0; k < 400; ++k) {
    const double t = 0.005 * k;
    samples.push_back({t, Eigen::Vector3d(0.1 * std::sin(t), 0.05, 0.3 * std::cos(2 * t)),
                       Eigen::Vector3d(2.0 * std::sin(3 * t), 0.5, 9.81)});
  }
  std::vector<ImuSample> planted = samples;
  planted[100].specific_force.x() = 1e5 * 0.999;  // a glitch past the range
  planted[200].angular_velocity.z() = 40.0;       // past 2000 deg/s
  planted[250].specific_force.z() = 9.81 + 60.0;  // a spike within the range: 6 g for one sample
  planted[300].angular_velocity.y() = 10.0;       // a 570 deg/s spike
  ImuNoise imu;
  const ImuScreening screening = ScreenImuSamples(planted, imu);
  EXPECT_EQ(screening.beyond_range, 2u);
  EXPECT_EQ(screening.spikes, 2u);
  ASSERT_EQ(planted.size(), samples.size() - 4);
  std::size_t kept = 0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (k == 100 || k == 200 || k == 250 || k == 300) continue;
    EXPECT_EQ(planted[kept++].stamp, samples[k].stamp);
  }
  // Motion is no spike: a step the next sample holds, and a clean drive, are kept whole.
  std::vector<ImuSample> step = samples;
  for (std::size_t k = 250; k < step.size(); ++k) step[k].specific_force.x() += 50.0;
  EXPECT_EQ(ScreenImuSamples(step, imu).spikes, 0u);
  std::vector<ImuSample> ramp = samples;  // 0, 45, 90 m/s^2 over three samples: steep, but motion
  for (std::size_t k = 300; k < ramp.size(); ++k)
    ramp[k].specific_force.x() = 45.0 * double(std::min<std::size_t>(k - 299, 2));
  EXPECT_EQ(ScreenImuSamples(ramp, imu).spikes, 0u);
  std::vector<ImuSample> clean = samples;
  const ImuScreening none = ScreenImuSamples(clean, imu);
  EXPECT_EQ(none.beyond_range + none.spikes, 0u);
  EXPECT_EQ(clean.size(), samples.size());
  // A narrower range drops what exceeds it: the 9.81 of gravity past a 9 m/s^2 accelerometer.
  imu.accel_range = 9.0;
  std::vector<ImuSample> narrow = samples;
  EXPECT_EQ(ScreenImuSamples(narrow, imu).beyond_range, samples.size());
}

TEST(ImuNoise, DefaultsPassAndNonPositiveDensitiesAreRefused) {
  ImuNoise noise;
  EXPECT_NO_THROW(CheckOptions(ImuNoiseOptionTable(), noise));
  noise.accel_noise_density = 0.0;
  EXPECT_THROW(CheckOptions(ImuNoiseOptionTable(), noise), std::invalid_argument);
}

}  // namespace
}  // namespace radargauss
