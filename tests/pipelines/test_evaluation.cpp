// SPDX-License-Identifier: BSD-3-Clause
// Trajectory evaluation against hand-computed figures: a constant scale
// drift, a constant rotation offset, rigid and similarity transforms of the
// estimate, time matching.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "radargauss/core/error.hpp"
#include "radargauss/experiment/evaluation.hpp"
#include "support/test_util.hpp"

namespace radargauss {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A straight drive along x at 1 m per pose (poses at t = k s), `poses` long.
Trajectory StraightDrive(int poses) {
  Trajectory drive;
  for (int k = 0; k < poses; ++k) drive.Append(k, SE3d(SO3d(), Eigen::Vector3d(k, 0.0, 0.0)));
  return drive;
}

// A curved drive with some climb and attitude changes.
Trajectory CurvedDrive() {
  Trajectory drive;
  for (int k = 0; k < 200; ++k) {
    const double s = 0.05 * k;
    drive.Append(0.1 * k, SE3d(SO3d::Exp(Eigen::Vector3d(0.02 * std::sin(s), 0.01 * s, s)),
                               Eigen::Vector3d(20.0 * std::sin(s), 20.0 * (1.0 - std::cos(s)), 0.3 * s)));
  }
  return drive;
}

Trajectory Transformed(const Trajectory& trajectory, const SE3d& left, double scale = 1.0) {
  Trajectory out;
  for (const StampedPose& sample : trajectory) {
    out.Append(sample.time, SE3d(left.rotation() * sample.pose.rotation(),
                                 scale * (left.rotation() * sample.pose.translation()) + left.translation()));
  }
  return out;
}

// Positions stretched by 2% along the drive: every segment drifts 2%, the
// position error grows to 2% of the distance (mean 1 m over 0..100 m).
TEST(Evaluation, ConstantScaleDrift) {
  const Trajectory reference = StraightDrive(101);
  Trajectory estimate;
  for (const StampedPose& sample : reference) {
    estimate.Append(sample.time, SE3d(SO3d(), 1.02 * sample.pose.translation()));
  }
  EvaluationOptions options;
  options.alignment = Alignment::kNone;
  const Evaluation e = EvaluateTrajectory(estimate, reference, options);
  EXPECT_EQ(e.matched, 101u);
  EXPECT_NEAR(e.path_length, 100.0, 1e-12);
  EXPECT_NEAR(e.ate_translation.mean, 1.0, 1e-12);
  EXPECT_NEAR(e.ate_translation.max, 2.0, 1e-12);
  ASSERT_EQ(e.rpe.size(), 5u);
  for (const SegmentDrift& d : e.rpe) {
    EXPECT_NEAR(d.translation, 2.0, 1e-9) << d.length;
    EXPECT_NEAR(d.horizontal, 2.0, 1e-9) << d.length;
    EXPECT_NEAR(d.rotation, 0.0, 1e-12) << d.length;
  }
  EXPECT_EQ(e.rpe[0].segments, 91u);  // starts 0..90 reach 10 m
  EXPECT_EQ(e.rpe[4].segments, 51u);
  EXPECT_TRUE(e.kitti.empty());  // no KITTI length below 100 m
}

// Every estimate pose turned by 3 deg about its own z: ATE rotation 3 deg
// everywhere; a segment's displacement d seen turned, |R^T d - d| = 2 sin(1.5 deg) |d|.
TEST(Evaluation, ConstantRotationOffset) {
  const Trajectory reference = StraightDrive(51);
  const SO3d offset = SO3d::Exp(Eigen::Vector3d(0.0, 0.0, 3.0 * kDeg));
  Trajectory estimate;
  for (const StampedPose& sample : reference) {
    estimate.Append(sample.time, SE3d(sample.pose.rotation() * offset, sample.pose.translation()));
  }
  EvaluationOptions options;
  options.alignment = Alignment::kNone;
  const Evaluation e = EvaluateTrajectory(estimate, reference, options);
  EXPECT_NEAR(e.ate_rotation.mean, 3.0, 1e-9);
  EXPECT_NEAR(e.ate_rotation.max, 3.0, 1e-9);
  EXPECT_NEAR(e.ate_translation.max, 0.0, 1e-12);
  for (const SegmentDrift& d : e.rpe) {
    EXPECT_NEAR(d.translation, 200.0 * std::sin(1.5 * kDeg), 1e-9);
    EXPECT_NEAR(d.rotation, 0.0, 1e-9);
  }
}

// ATE after SE3 alignment does not change under a rigid transform of the
// estimate; Sim3 also undoes a scale, in the ATE and the RPE; the first-pose alignment undoes a
// transform exactly; RPE ignores a rigid transform altogether.
TEST(Evaluation, AlignmentsUndoTransformsOfTheEstimate) {
  const Trajectory reference = CurvedDrive();
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  Trajectory noisy;
  for (const StampedPose& sample : reference) {
    noisy.Append(sample.time, SE3d(sample.pose.rotation() * SO3d::Exp(Eigen::Vector3d(noise(rng), 0.0, noise(rng))),
                                   sample.pose.translation() + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))));
  }
  const SE3d moved(SO3d::Exp(Eigen::Vector3d(0.3, -0.2, 1.2)), Eigen::Vector3d(40.0, -7.0, 3.0));
  const Evaluation plain = EvaluateTrajectory(noisy, reference);
  const Evaluation rigid = EvaluateTrajectory(Transformed(noisy, moved), reference);
  EXPECT_NEAR(rigid.ate_translation.rmse, plain.ate_translation.rmse, 1e-9);
  EXPECT_NEAR(rigid.ate_rotation.rmse, plain.ate_rotation.rmse, 1e-9);
  EXPECT_NEAR(rigid.rpe_mean.translation, plain.rpe_mean.translation, 1e-9);
  EXPECT_GT(plain.ate_translation.rmse, 0.05);  // the noise is there

  EvaluationOptions sim3;
  sim3.alignment = Alignment::kSim3;
  const Evaluation scaled = EvaluateTrajectory(Transformed(reference, moved, 0.8), reference, sim3);
  EXPECT_NEAR(scaled.scale, 1.25, 1e-9);
  EXPECT_LT(scaled.ate_translation.max, 1e-9);
  EXPECT_LT(scaled.ate_rotation.max, 1e-6);
  EXPECT_LT(scaled.rpe_mean.translation, 1e-7);  // the scale is undone in the RPE too

  EvaluationOptions first;
  first.alignment = Alignment::kFirst;
  const Evaluation exact = EvaluateTrajectory(Transformed(reference, moved), reference, first);
  EXPECT_LT(exact.ate_translation.max, 1e-9);
  EXPECT_LT(exact.rpe_mean.translation, 1e-9);
}

// Poses pair by the nearest time within the tolerance; too few pairs is an error.
// Positions on a line leave the rotation about it free: Umeyama on a
// straight drive with 5 cm of noise gave 1 deg or 179 deg by the noise's
// draw. The alignment takes its rotation from the orientations there, says
// so, and gives the planted 0.8 deg whatever the draw, the estimate's frame,
// or the 9 decimals of the TUM files it went through.
TEST(Evaluation, PositionsOnALineTakeTheRotationFromTheOrientations) {
  const Trajectory reference = StraightDrive(72);
  for (const std::uint32_t seed : {1u, 2u, 3u, 4u, 5u}) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.05);
    Trajectory estimate;
    for (const StampedPose& sample : reference) {
      // Rolled +-0.8 deg about the line itself, in turn: no mean offset to align away.
      const double roll = (int(sample.time) % 2 == 0 ? 0.8 : -0.8) * kDeg;
      estimate.Append(sample.time,
                      SE3d(sample.pose.rotation() * SO3d::Exp(Eigen::Vector3d(roll, 0.0, 0.0)),
                           sample.pose.translation() + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))));
    }
    const SE3d moved(SO3d::Exp(Eigen::Vector3d(0.3, -0.2, 1.2)), Eigen::Vector3d(40.0, -7.0, 3.0));
    for (const Trajectory& input : {estimate, Transformed(estimate, moved)}) {
      const Evaluation e = EvaluateTrajectory(input, reference);
      EXPECT_EQ(e.alignment_note, "rotation from the orientations: the reference positions lie on a line");
      EXPECT_NEAR(e.ate_rotation.max, 0.8, 1e-9) << seed;
      EXPECT_NEAR(e.ate_rotation.mean, 0.8, 1e-9) << seed;
      EXPECT_LT(e.ate_translation.rmse, 0.15) << seed;
    }
    // Through TUM files (9 decimals), as `radargauss evaluate` reads them: the same figures.
    const Evaluation in_memory = EvaluateTrajectory(estimate, reference);
    const std::string path = ::testing::TempDir() + "/straight_" + std::to_string(seed) + ".tum";
    WriteTum(path, estimate);
    const Evaluation from_file = EvaluateTrajectory(ReadTum(path), reference);
    EXPECT_NEAR(from_file.ate_rotation.rmse, in_memory.ate_rotation.rmse, 1e-6);
    EXPECT_NEAR(from_file.ate_translation.rmse, in_memory.ate_translation.rmse, 1e-6);
    EXPECT_NEAR(from_file.rpe_mean.translation, in_memory.rpe_mean.translation, 1e-6);
  }
  // A drive with a corner determines the rotation by its positions: Umeyama, no note.
  EXPECT_EQ(EvaluateTrajectory(CurvedDrive(), CurvedDrive()).alignment_note, "");
  // Sim3 on a line: the scale from the spreads, the rotation from the orientations.
  EvaluationOptions sim3;
  sim3.alignment = Alignment::kSim3;
  const Evaluation scaled = EvaluateTrajectory(Transformed(reference, SE3d(), 0.8), reference, sim3);
  EXPECT_NEAR(scaled.scale, 1.25, 1e-9);
  EXPECT_LT(scaled.ate_translation.max, 1e-9);
}

TEST(Evaluation, MatchesPosesByTime) {
  const Trajectory reference = StraightDrive(30);
  Trajectory shifted;
  for (const StampedPose& sample : reference) shifted.Append(sample.time + 0.01, sample.pose);
  EXPECT_EQ(EvaluateTrajectory(shifted, reference).matched, 30u);
  EvaluationOptions strict;
  strict.time_tolerance = 0.005;
  EXPECT_THROW(EvaluateTrajectory(shifted, reference, strict), DataError);
  EXPECT_THROW(AlignmentFromString("sim4"), std::invalid_argument);
  EXPECT_EQ(ToString(AlignmentFromString("first")), "first");
}

// KITTI segments of 100-800 m, those shorter than the path.
TEST(Evaluation, KittiSegmentsShorterThanThePath) {
  const Evaluation e = EvaluateTrajectory(StraightDrive(451), StraightDrive(451));
  ASSERT_EQ(e.kitti.size(), 4u);  // 100, 200, 300, 400 m below 450 m
  EXPECT_EQ(e.kitti[3].segments, 51u);
  EXPECT_NEAR(e.kitti[0].translation, 0.0, 1e-12);
}

}  // namespace
}  // namespace radargauss
