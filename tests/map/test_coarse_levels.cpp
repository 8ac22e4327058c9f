// SPDX-License-Identifier: BSD-3-Clause
// The coarse levels of a MatchingMap: merged and inflated levels, their gate,
// voxel centroids and strided points, their tolerances.

#include <ceres/cost_function.h>
#include <ceres/crs_matrix.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <iterator>
#include <memory>
#include <cctype>
#include <cmath>
#include <limits>
#include <random>

#include "radargauss/experiment/experiment.hpp"
#include "radargauss/lie/manifold.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/core/sh.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "radargauss/residuals/geometric_residual.hpp"
#include "radargauss/residuals/loss.hpp"
#include "radargauss/residuals/rcs_residual.hpp"
#include "radargauss/solvers/ceres_solver.hpp"
#include "radargauss/solvers/factory.hpp"
#include "radargauss/solvers/gauss_newton.hpp"
#include "radargauss/solvers/multi_hypothesis.hpp"
#include "radargauss/solvers/joint_refinement.hpp"
#include "support/scan_matching_fixtures.hpp"

namespace radargauss {
namespace {

using testing::NumericJacobian;
using testing::RandomUnitVector;

// coarse_points subsamples the coarse levels only: a limit above the scan
// size changes nothing, a small one changes the path.
TEST(CoarsePoints, SubsamplesCoarseLevelsOnly) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const SE3d initial = Perturbed(world.simulated.ground_truth[kTestScan].pose, 2.0, 5.0, 1);
  ScanMatchingOptions all, above, few;
  above.coarse_points = scan.points.size() + 1;
  few.coarse_points = 20;
  const SE3d a = GaussNewtonSolver(all).Match(scan, *world.matching, initial).pose;
  const SE3d b = GaussNewtonSolver(above).Match(scan, *world.matching, initial).pose;
  const SE3d c = GaussNewtonSolver(few).Match(scan, *world.matching, initial).pose;
  EXPECT_EQ(a.translation(), b.translation());
  EXPECT_NE(a.translation(), c.translation());
}

// The coarse levels stop on their own tolerances, the exact map on its own:
// coarse tolerances so large that every first step is small end each coarse
// level after one iteration (the exact map's iterations unchanged in kind),
// and invalid ones are rejected.
TEST(CoarseTolerances, EndCoarseLevelsOnly) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const SE3d initial = Perturbed(world.simulated.ground_truth[kTestScan].pose, 2.0, 5.0, 1);
  ScanMatchingOptions loose;
  loose.coarse_translation_tolerance = 1e3;
  loose.coarse_rotation_tolerance = 1e3;
  const ScanMatchingResult defaults = GaussNewtonSolver(ScanMatchingOptions{}).Match(scan, *world.matching, initial);
  ScanMatchingOptions exact_only = loose;
  exact_only.max_iterations = 1;  // one iteration on the exact map: the coarse levels' count is what remains
  const ScanMatchingResult one = GaussNewtonSolver(exact_only).Match(scan, *world.matching, initial);
  EXPECT_EQ(one.iterations, int(world.matching->levels()));
  EXPECT_GT(defaults.iterations, int(world.matching->levels()) + 1);
  ScanMatchingOptions bad;
  bad.coarse_translation_tolerance = 0.0;
  EXPECT_THROW(GaussNewtonSolver{bad}, std::invalid_argument);
  bad = ScanMatchingOptions{};
  bad.coarse_rotation_tolerance = -1.0;
  EXPECT_THROW(CeresSolver{bad}, std::invalid_argument);
}

// Merged coarse levels: the Gaussians whose means share a voxel of side
// kMergeCellPerSigma * sigma become their moment-matched mixture (weights:
// member counts), blurred by sigma^2 I. Reference by hand: two Gaussians
// a = 2 m apart along x with weights 1 and 3 merge to the weighted mean and
// Sigma_mix = sum w_i Sigma_i / W + (w1 w2 / W^2) a^2 e_x e_x^T.
TEST(MergedCoarseLevels, MomentMatchedMixturePerVoxel) {
  GaussianMap map;
  Gaussian first, second, far;
  first.mean = Eigen::Vector3d(0.2, 0.5, 0.5);
  first.covariance = Eigen::Vector3d(0.04, 0.09, 0.01).asDiagonal();
  first.point_count = 1;
  second.mean = Eigen::Vector3d(2.2, 0.5, 0.5);
  second.covariance = 0.01 * Eigen::Matrix3d::Identity();
  second.point_count = 3;
  far.mean = Eigen::Vector3d(20.0, 0.5, 0.5);
  far.covariance = 0.01 * Eigen::Matrix3d::Identity();
  far.point_count = 2;
  map.gaussians = {first, second, far};
  MatchingMapOptions options;
  options.inflation = {1.0};
  options.coarse = CoarseLevels::kMerged;
  const MatchingMap matching(map, options);
  ASSERT_EQ(matching.levels(), 2u);
  const GaussianIndex& coarse = matching.level(0);
  ASSERT_EQ(coarse.size(), 2u);  // {first, second} and {far}
  const std::size_t merged = coarse.Mean(0).x() < 10.0 ? 0 : 1;
  const Eigen::Vector3d expected_mean(0.25 * 0.2 + 0.75 * 2.2, 0.5, 0.5);
  Eigen::Matrix3d expected_covariance = 0.25 * first.covariance + 0.75 * second.covariance;
  expected_covariance(0, 0) += 0.25 * 0.75 * 2.0 * 2.0;
  expected_covariance += Eigen::Matrix3d::Identity();  // sigma = 1
  EXPECT_LT((coarse.Mean(merged) - expected_mean).norm(), 1e-12);
  EXPECT_LT((coarse.Information(merged).inverse() - expected_covariance).norm(), 1e-9);
  const Eigen::Matrix3d far_covariance = far.covariance + Eigen::Matrix3d::Identity();
  EXPECT_LT((coarse.Mean(1 - merged) - far.mean).norm(), 1e-12);
  EXPECT_LT((coarse.Information(1 - merged).inverse() - far_covariance).norm(), 1e-9);
  // The exact level is the map itself.
  EXPECT_EQ(matching.index().size(), 3u);
  // Index cells: half the merge cell on a merged level, sigma on an inflated
  // one, at least index_cell.
  EXPECT_EQ(coarse.cell_size(), 1.5);
  EXPECT_EQ(matching.index().cell_size(), options.index_cell);
  options.coarse = CoarseLevels::kInflated;
  options.inflation = {1.0, 0.25};
  const MatchingMap inflated(map, options);
  EXPECT_EQ(inflated.level(0).cell_size(), 1.0);
  EXPECT_EQ(inflated.level(1).cell_size(), options.index_cell);
  EXPECT_THROW(CoarseLevelsFromString("blurred"), std::invalid_argument);
  EXPECT_EQ(CoarseLevelsFromString(ToString(CoarseLevels::kMerged)), CoarseLevels::kMerged);
}

// With merged coarse levels (matching the scan's voxel centroids or 400 of
// its points there, and with a coarse gate of 2) the solvers still reach
// 5 cm / 0.2 deg on the test scan from 2 m / 5 deg.
TEST(MergedCoarseLevels, ConvergesFromTwoMetresFiveDegrees) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  for (const double coarse_gate : {3.0, 2.0}) {
    MatchingMapOptions merged_options;
    merged_options.coarse = CoarseLevels::kMerged;
    merged_options.coarse_gate = coarse_gate;
    const MatchingMap merged(world.map, merged_options);
    ASSERT_LT(merged.level(0).size(), world.map.gaussians.size() / 4);  // an inflated level holds them all
    for (const std::string name : {"gn", "ceres"}) {
      for (const double w : {0.0, 0.25}) {
        for (const std::size_t coarse_points : {std::size_t(0), std::size_t(400)}) {
          ScanMatchingOptions options;
          options.w_rcs = w;
          options.coarse_points = coarse_points;
          options.coarse_voxel_per_sigma = coarse_points > 0 ? 0.0 : 2.0;  // the points, or voxel centroids
          const auto solver = MakeSolver(name, options);
          for (const std::uint32_t seed : {1u, 2u, 3u}) {
            const ScanMatchingResult result = solver->Match(scan, merged, Perturbed(truth, 2.0, 5.0, seed));
            double dt = 0.0, dr = 0.0;
            PoseErrors(result.pose, truth, dt, dr);
            const std::string where = name + " w " + std::to_string(w) + " coarse points " +
                                      std::to_string(coarse_points) + " coarse gate " + std::to_string(coarse_gate) +
                                      " seed " + std::to_string(seed);
            EXPECT_TRUE(result.converged) << result.reason << " " << where;
            EXPECT_LT(dt, 0.05) << where;
            EXPECT_LT(dr, 0.2) << where;
          }
        }
      }
    }
  }
}

// The coarse gate: on a coarse level a point goes to a blurred Gaussian only
// within coarse_gate (the exact map keeps ScanMatchingOptions::gate), and the
// level's index lists a Gaussian only in the cells of its +/- coarse_gate box.
// One Gaussian at the origin, Sigma = 0.01 I, blurred by sigma = 1 m:
// Sigma_1 = 1.01 I, so a point at radius r is r / 1.005 blurred std away.
TEST(CoarseGate, CoarseLevelsAssociateWithinIt) {
  const GaussianMap map = OneGaussianAtTheOrigin();
  const RadarScan scan = ScanOf({Eigen::Vector3d(1.5, 0, 0), Eigen::Vector3d(0, 1.5, 0), Eigen::Vector3d(0, 0, -1.5),
                                 Eigen::Vector3d(2.6, 0, 0), Eigen::Vector3d(0, -2.6, 0), Eigen::Vector3d(0, 0, 2.6)});
  ScanMatchingOptions options;           // gate 3 on the exact map
  options.coarse_voxel_per_sigma = 0.0;  // the points themselves
  for (const double coarse_gate : {3.0, 2.0}) {
    MatchingMapOptions map_options;
    map_options.inflation = {1.0};
    map_options.coarse_gate = coarse_gate;
    const MatchingMap matching(map, map_options);
    EXPECT_EQ(matching.coarse_gate(), coarse_gate);
    std::vector<std::size_t> associated;  // per level visited
    const ScanPriors none;
    CoarseToFine match(scan, matching, SE3d(), options, none);
    for (const Stage& stage : match.stages()) {
      if (!match.Associate(stage, 1)) break;
      associated.push_back(match.correspondences().geometric.size());
    }
    const ScanMatchingResult result = match.Failed();
    // The coarse level: the 1.5 m points (1.49 std) always, the 2.6 m ones
    // (2.59 std) only within a gate of 3. The exact map (0.1 m std): none.
    ASSERT_EQ(associated.size(), 1u);
    EXPECT_EQ(associated[0], coarse_gate > 2.59 ? 6u : 3u);
    EXPECT_FALSE(result.converged);
    EXPECT_EQ(result.reason, "no point associated to the map");
    // Cells of side 1 m: the cell of x = 3.2 m meets the ellipsoid of 3 std
    // (to 3.015 m), not that of 2 std (2.01 m).
    std::size_t count = 0;
    matching.level(0).Candidates(Eigen::Vector3d(3.2, 0.0, 0.0), count);
    EXPECT_EQ(count, coarse_gate == 3.0 ? 1u : 0u);
  }
  MatchingMapOptions bad;
  bad.coarse_gate = 0.0;
  EXPECT_THROW(MatchingMap(map, bad), std::invalid_argument);
}

// Coarse voxels: each coarse level matches the centroids of the scan's voxels
// of side coarse_voxel_per_sigma * sigma_k (then at most coarse_points of
// them, evenly strided). One Gaussian at the origin, levels blurred by 1 and
// 0.5 m, voxels of 2 and 1 m; the centroids by hand.
TEST(CoarseVoxels, CoarseLevelsMatchTheScansVoxelCentroids) {
  const GaussianMap map = OneGaussianAtTheOrigin();
  const Eigen::Vector3d a(0.2, 0.2, 0.2), b(0.6, 0.4, 0.2), c(1.4, 0.2, 0.2), d(-0.5, 0.3, 0.2);
  const RadarScan scan = ScanOf({a, b, c, d});
  MatchingMapOptions map_options;
  map_options.inflation = {1.0, 0.5};
  const MatchingMap matching(map, map_options);
  EXPECT_EQ(matching.sigma(0), 1.0);
  EXPECT_EQ(matching.sigma(1), 0.5);
  EXPECT_EQ(matching.sigma(2), 0.0);  // the exact map
  const auto coarse_points = [&](const ScanMatchingOptions& options) {
    std::vector<std::vector<Eigen::Vector3d>> levels;  // the associated points, per coarse level
    const ScanPriors none;
    CoarseToFine match(scan, matching, SE3d(), options, none);
    for (const Stage& stage : match.stages()) {
      if (stage.finest || !match.Associate(stage, 1)) break;
      levels.emplace_back();
      for (const GeometricTerm& term : match.correspondences().geometric) levels.back().push_back(term.point_radar);
    }
    return levels;
  };
  const auto expect_points = [](const std::vector<Eigen::Vector3d>& got, const std::vector<Eigen::Vector3d>& want,
                                const std::string& where) {
    ASSERT_EQ(got.size(), want.size()) << where;
    for (std::size_t k = 0; k < want.size(); ++k) EXPECT_LT((got[k] - want[k]).norm(), 1e-12) << where << " " << k;
  };
  ScanMatchingOptions options;
  options.coarse_voxel_per_sigma = 2.0;
  auto levels = coarse_points(options);
  ASSERT_EQ(levels.size(), 2u);
  expect_points(levels[0], {(a + b + c) / 3.0, d}, "2 m voxels");  // in the order of their first points
  expect_points(levels[1], {(a + b) / 2.0, c, d}, "1 m voxels");
  options.coarse_points = 2;  // of the centroids, evenly strided
  levels = coarse_points(options);
  ASSERT_EQ(levels.size(), 2u);
  expect_points(levels[0], {(a + b + c) / 3.0, d}, "2 m voxels, 2 points");
  expect_points(levels[1], {(a + b) / 2.0, c}, "1 m voxels, 2 points");
  ScanMatchingOptions points;
  points.coarse_voxel_per_sigma = 0.0;  // without voxels: the points themselves
  levels = coarse_points(points);
  ASSERT_EQ(levels.size(), 2u);
  expect_points(levels[0], {a, b, c, d}, "points");
  ScanMatchingOptions bad;
  bad.coarse_voxel_per_sigma = -1.0;
  EXPECT_THROW(GaussNewtonSolver{bad}, std::invalid_argument);
  bad.coarse_voxel_per_sigma = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(CeresSolver{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace radargauss
