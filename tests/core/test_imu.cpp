// SPDX-License-Identifier: BSD-3-Clause
// IMU files (io/imu.hpp): planted samples read back exactly, every malformed
// line refused naming its line, the summary's rate, gaps and means against a
// planted file, the extrinsic file, and the noise options' table.
#include <gtest/gtest.h>

#include <cstdio>
#include <stdexcept>
#include <string>

#include "radargauss/error.hpp"
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
  WriteFile("T_radar_imu.txt", "0 0 nan 0 0 0 1\n");
  EXPECT_THROW(ReadExtrinsicFile(path), DataError);
}

TEST(ImuNoise, DefaultsPassAndNonPositiveDensitiesAreRefused) {
  ImuNoise noise;
  EXPECT_NO_THROW(CheckOptions(ImuNoiseOptionTable(), noise));
  noise.accel_noise_density = 0.0;
  EXPECT_THROW(CheckOptions(ImuNoiseOptionTable(), noise), std::invalid_argument);
}

}  // namespace
}  // namespace radargauss
