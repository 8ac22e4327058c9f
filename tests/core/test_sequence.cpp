// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/sequence.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "radargauss/core/error.hpp"
#include "radargauss/io/kitti_bin.hpp"
#include "radargauss/io/pcd.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

namespace fs = std::filesystem;
using testing::SharedData;
using KittiBin = testing::TempDirTest;
using SequenceFiles = testing::TempDirTest;

std::string Records(const std::vector<std::vector<float>>& rows) {
  std::string bytes;
  for (const auto& row : rows) bytes.append(reinterpret_cast<const char*>(row.data()), row.size() * 4);
  return bytes;
}

TEST_F(KittiBin, ReadsViewOfDelftLayout) {
  const std::string path =
      WriteFile("00042.bin", Records({{10, 1, 0.5, -3, 2.5, 0.1, 0}, {20, -2, 1.0, 7, -1.5, 0.0, 0}}));
  const RadarScan scan = ReadKittiBin(path, ParseBinLayout("vod"));
  ASSERT_EQ(scan.points.size(), 2u);
  EXPECT_EQ(scan.points[1].position, Eigen::Vector3d(20, -2, 1));
  EXPECT_EQ(scan.points[0].rcs, -3.0);
  EXPECT_EQ(scan.points[1].doppler, -1.5);  // v_r, not v_r_comp
  FieldMapping mapping;
  mapping.doppler_field = "v_r_comp";
  EXPECT_EQ(ReadKittiBin(path, ParseBinLayout("vod"), mapping).points[0].doppler, float(0.1));
}

TEST_F(KittiBin, RejectsTruncatedFilesAndBadLayouts) {
  const std::string path = WriteFile("bad.bin", Records({{1, 2, 3, 4, 5, 6, 7}}).substr(0, 26));
  try {
    ReadKittiBin(path, ParseBinLayout("vod"));
    FAIL();
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("not a whole number of 28-byte records"), std::string::npos);
  }
  const std::string nan_path = WriteFile("nan.bin", Records({{1, NAN, 3}}));
  EXPECT_THROW(ReadKittiBin(nan_path, ParseBinLayout("x y z")), DataError);
  EXPECT_THROW(ParseBinLayout("x y"), std::invalid_argument);
  EXPECT_THROW(ParseBinLayout("x y z x"), std::invalid_argument);
  EXPECT_EQ(ParseBinLayout("x,y,z,rcs").size(), 4u);
}

// Independent derivation: T_xt32_ars548 = T_body_xt32^-1 T_body_ars548 with
// R_body_x36d = R_body_xt32 R_x36d_xt32^T simplifies to R_x36d_xt32^T R_x36d_ars548.
TEST(Extrinsic, SnailRadarPresetMatchesAlgebra) {
  Eigen::Matrix3d R_x36d_xt32;
  R_x36d_xt32 << -0.001402106, -0.999967799, 0.007901562, 0.999997759, -0.001414596, -0.001575345, 0.001586472,
      0.007899336, 0.999967541;
  Eigen::Matrix3d R_x36d_ars548;
  R_x36d_ars548 << 0.99912647794293, 0.039117559886893, -0.0147002578838332, -0.0390210149947843, 0.999215265264576,
      0.00679809171902766, 0.0149546468407877, -0.00621853445265288, 0.999868835581512;
  const SE3d extrinsic = SnailRadar20231213Extrinsic();
  EXPECT_LT((extrinsic.rotation().Matrix() - R_x36d_xt32.transpose() * R_x36d_ars548).norm(), 1e-5);
  EXPECT_LT((extrinsic.translation() - Eigen::Vector3d(0, 0, 0.07)).norm(), 1e-12);
  // The radar looks along the lidar's -y... rather: roughly a -90 deg yaw.
  EXPECT_NEAR(extrinsic.rotation().Log().z(), -M_PI / 2, 0.05);
}

TEST_F(SequenceFiles, ExtrinsicSpecs) {
  EXPECT_EQ(ResolveExtrinsic("auto", "/x/utm50r_T_xt32.txt").translation().z(), 0.07);
  EXPECT_EQ(ResolveExtrinsic("auto", "/x/gt_tum.txt").translation().z(), 0.0);
  const SE3d from_file = ResolveExtrinsic(WriteFile("ext.txt", "# T_gt_radar\n1 2 3 0 0 0 1\n"), "");
  EXPECT_EQ(from_file.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_THROW(ResolveExtrinsic("snail-2099", ""), DataError);
  EXPECT_THROW(ResolveExtrinsic(WriteFile("short.txt", "1 2 3 0 0 1\n"), ""), DataError);
  EXPECT_THROW(ResolveExtrinsic(WriteFile("long.txt", "1 2 3 0 0 0 1 9\n"), ""), DataError);
  EXPECT_THROW(ResolveExtrinsic(WriteFile("nonunit.txt", "1 2 3 0 0 0 2\n"), ""), DataError);
}

TEST_F(SequenceFiles, BadSequencesGiveErrors) {
  SequenceOptions options;
  EXPECT_THROW(LoadSequence(options), DataError);
  options.sequence_dir = Path("absent");
  EXPECT_THROW(LoadSequence(options), DataError);
  options.sequence_dir = dir_.string();
  EXPECT_THROW(LoadSequence(options), DataError);  // no scans
  RadarScan scan;
  scan.points.push_back(RadarPoint{});
  WritePcdScan(Path("5.000000000.pcd"), scan);
  WritePcdScan(Path("6.000000000.pcd"), scan);
  options.ground_truth = WriteFile("gt.txt", "0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n");
  EXPECT_THROW(LoadSequence(options), DataError);  // no scan inside the trajectory
  options.ground_truth = WriteFile("gt2.txt", "0 0 0 0 0 0 0 1\n5.5 1 0 0 0 0 0 1\n");
  const Sequence sequence = LoadSequence(options);
  EXPECT_EQ(sequence.layout, "pcd-folder");
  EXPECT_EQ(sequence.scans.size(), 1u);
  EXPECT_EQ(sequence.skipped_scans, 1u);
  EXPECT_NEAR(sequence.poses[0].translation().x(), 5.0 / 5.5, 1e-12);
}

// The NTU Eagle sample: 500 scans, 497 with poses (frames 498-500 have none).
TEST(SequenceRealData, NtuEagleMatchesScansToPoses) {
  const std::string dir = SharedData("ntu4dradlm_loop1_eagle");
  if (dir.empty()) GTEST_SKIP() << "shared data not found";
  SequenceOptions options;
  options.sequence_dir = dir + "/points";
  options.ground_truth = dir + "/gt_tum.txt";
  const Sequence sequence = LoadSequence(options);
  EXPECT_EQ(sequence.layout, "pcd-folder");
  EXPECT_EQ(sequence.total_scans, 500u);
  EXPECT_EQ(sequence.scans.size(), 497u);
  EXPECT_EQ(sequence.skipped_scans, 3u);
  EXPECT_EQ(sequence.poses.size(), 497u);
  EXPECT_EQ(sequence.extrinsic.translation(), Eigen::Vector3d::Zero());
  // Matched exactly at the ground-truth samples (same time strings).
  EXPECT_LT((sequence.poses[10].Matrix() - sequence.trajectory[10].pose.Matrix()).norm(), 1e-12);
}

}  // namespace
}  // namespace radargauss
