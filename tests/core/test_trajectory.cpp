// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/core/trajectory.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include "radargauss/core/error.hpp"
#include "support/test_util.hpp"

namespace radargauss {
namespace {

namespace fs = std::filesystem;
using testing::RandomUnitVector;

class TrajectoryFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("radargauss_traj_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& content) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << content;
    return path;
  }

  // Expects ReadTum to throw DataError whose message names the file, the
  // line and contains `fault`.
  void ExpectError(const std::string& content, std::size_t line, const std::string& fault) {
    const std::string path = Write("bad.txt", content);
    try {
      ReadTum(path);
      FAIL() << "no error for:\n" << content;
    } catch (const DataError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path + ":" + std::to_string(line) + ":"), std::string::npos) << message;
      EXPECT_NE(message.find(fault), std::string::npos) << message;
    }
  }

  fs::path dir_;
};

constexpr const char* kGood = "0.0 0 0 0 0 0 0 1\n";

TEST_F(TrajectoryFiles, RoundTripIsExactToPrintedPrecision) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> uniform(-100.0, 100.0);
  Trajectory original;
  double time = 1702450000.0;
  for (int i = 0; i < 100; ++i) {
    time += 0.05 + 0.01 * std::abs(uniform(rng)) / 100.0;
    original.Append(
        time, SE3d(SO3d::Exp(3.0 * RandomUnitVector(rng)), Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng))));
  }
  const std::string path = (dir_ / "round_trip.txt").string();
  WriteTum(path, original);
  const Trajectory read = ReadTum(path);
  ASSERT_EQ(read.size(), original.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    // 9 printed decimals: half a unit in the last place, plus the double's own
    // resolution at 1.7e9 s for the time stamp.
    EXPECT_NEAR(read[i].time, original[i].time, 5e-10 + 2.4e-7);
    EXPECT_LT((read[i].pose.translation() - original[i].pose.translation()).cwiseAbs().maxCoeff(), 5e-10 + 1e-14);
    // Normalisation after reading moves a component by at most ~1e-9.
    EXPECT_LT((read[i].pose.rotation().quaternion().coeffs() - original[i].pose.rotation().quaternion().coeffs())
                  .cwiseAbs()
                  .maxCoeff(),
              2e-9);
  }
  // Writing what was read gives the same file again, up to the last digit of
  // the renormalised quaternion.
  const std::string again = (dir_ / "again.txt").string();
  WriteTum(again, read);
  EXPECT_EQ(ReadTum(again).size(), original.size());
}

TEST_F(TrajectoryFiles, SkipsCommentsAndBlankLines) {
  const Trajectory t = ReadTum(Write("ok.txt", "# t x y z qx qy qz qw\n\n   \n" + std::string(kGood) +
                                                   "1.5 1 2 3 0 0 0.7071067811865476 "
                                                   "0.7071067811865476\r\n"));
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[1].time, 1.5);
  EXPECT_EQ(t[1].pose.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_NEAR(t[1].pose.rotation().Log().z(), M_PI / 2, 1e-12);
}

TEST_F(TrajectoryFiles, MalformedLinesNameFileAndLine) {
  ExpectError(std::string(kGood) + "1.0 0 0 0 0 0 1\n", 2, "expected 8 columns");
  ExpectError(std::string(kGood) + "1.0 0 0 0 0 0 0 1 9\n", 2, "expected 8 columns");
  ExpectError("# header\n0.0 0 zero 0 0 0 0 1\n", 2, "not a number: 'zero'");
  ExpectError("0.0 0 0 0 0 0 0 1.5x\n", 1, "not a number");
  ExpectError("0.0 0 0 0 0 0 0 1.1\n", 1, "quaternion norm");
  ExpectError("0.0 0 0 0 0 0 0 0\n", 1, "quaternion norm");
  ExpectError("0.0 nan 0 0 0 0 0 1\n", 1, "non-finite");
  ExpectError(std::string(kGood) + "0.0 0 0 0 0 0 0 1\n", 2, "time does not increase");
  ExpectError(std::string(kGood) + "-1.0 0 0 0 0 0 0 1\n", 2, "time does not increase");
}

TEST_F(TrajectoryFiles, MissingFileIsAnError) { EXPECT_THROW(ReadTum((dir_ / "absent.txt").string()), DataError); }

TEST_F(TrajectoryFiles, FailedWriteLeavesNoFile) {
  const fs::path target = dir_ / "no_such_dir" / "out.txt";
  Trajectory t;
  t.Append(0.0, SE3d());
  EXPECT_THROW(WriteTum(target.string(), t), DataError);
  EXPECT_FALSE(fs::exists(target));
}

TEST(Trajectory, RejectsNonIncreasingTimes) {
  Trajectory t;
  t.Append(1.0, SE3d());
  EXPECT_THROW(t.Append(1.0, SE3d()), std::invalid_argument);
  EXPECT_THROW(t.Append(NAN, SE3d()), std::invalid_argument);
  EXPECT_THROW(Trajectory({{2.0, SE3d()}, {1.0, SE3d()}}), std::invalid_argument);
}

// Planted motion with constant body angular rate and constant world velocity:
// slerp + linear interpolation reproduces it exactly between samples.
TEST(Trajectory, InterpolationReproducesPlantedMotion) {
  const SO3d r0 = SO3d::Exp(Eigen::Vector3d(0.1, -0.2, 0.3));
  const Eigen::Vector3d omega(0.05, 0.1, -0.4);  // rad/s, body frame
  const Eigen::Vector3d t0(1.0, 2.0, 3.0);
  const Eigen::Vector3d velocity(4.0, -1.0, 0.2);  // m/s, world frame
  const auto truth = [&](double time) { return SE3d(r0 * SO3d::Exp(time * omega), t0 + time * velocity); };
  Trajectory trajectory;
  for (int i = 0; i <= 10; ++i) trajectory.Append(0.5 * i, truth(0.5 * i));
  for (const double time : {0.0, 0.1, 0.37, 1.0, 2.49, 4.999, 5.0}) {
    const std::optional<SE3d> pose = trajectory.Interpolate(time);
    ASSERT_TRUE(pose.has_value()) << time;
    EXPECT_LT((pose->Matrix() - truth(time).Matrix()).norm(), 1e-12) << time;
  }
  EXPECT_FALSE(trajectory.Interpolate(-0.01).has_value());
  EXPECT_FALSE(trajectory.Interpolate(5.01).has_value());
  EXPECT_FALSE(trajectory.Interpolate(NAN).has_value());
  EXPECT_FALSE(Trajectory().Interpolate(0.0).has_value());
}

TEST(Trajectory, RightMultipliedAppliesExtrinsic) {
  Trajectory body;
  body.Append(0.0, SE3d(SO3d::Exp(Eigen::Vector3d(0, 0, 1)), Eigen::Vector3d(1, 0, 0)));
  const SE3d body_radar(SO3d::Exp(Eigen::Vector3d(0.1, 0, 0)), Eigen::Vector3d(0, 0, 0.07));
  const Trajectory radar = body.RightMultiplied(body_radar);
  EXPECT_LT((radar[0].pose.Matrix() - (body[0].pose * body_radar).Matrix()).norm(), 1e-15);
}

// The NTU Eagle sample's recommended ground truth (see shared/data).
TEST(TrajectoryRealData, ReadsNtuGroundTruth) {
  const fs::path path = fs::path(RADARGAUSS_SHARED_DATA_DIR) / "ntu4dradlm_loop1_eagle" / "gt_tum.txt";
  if (!fs::exists(path)) GTEST_SKIP() << "shared data not found at " << path;
  const Trajectory t = ReadTum(path.string());
  EXPECT_EQ(t.size(), 497u);
  EXPECT_EQ(t.StartTime(), 0.0);
  EXPECT_NEAR(t[0].pose.translation().x(), 0.879913, 1e-12);
  double length = 0.0;
  for (std::size_t i = 1; i < t.size(); ++i) {
    length += (t[i].pose.translation() - t[i - 1].pose.translation()).norm();
  }
  EXPECT_NEAR(length, 223.0, 3.0);  // "223 m" in the data README
}

}  // namespace
}  // namespace radargauss
