// SPDX-License-Identifier: BSD-3-Clause
// The spatial index: association against brute force, cell culling.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <random>
#include <set>

#include "radargauss/core/error.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "radargauss/core/voxel_grid.hpp"
#include "support/temp_dir.hpp"
#include "support/map_fixtures.hpp"

namespace radargauss {
namespace {

using testing::RandomUnitVector;

// The index gives the brute-force answer: every point within tau <= 3 of a
// Gaussian lies in a cell its 3-sigma ellipsoid meets. So does the batched
// query (AssociateAll), which fetches ahead and must not change an answer.
TEST(GaussianIndexTest, MatchesBruteForceAssociation) {
  const Planted planted = PlantGaussians(10, 3);
  const GaussianIndex index(planted.gaussians, 0.7);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> uniform(-2.0, 20.0);
  int associated = 0;
  std::vector<Eigen::Vector3d> points;
  std::vector<int> expected_all;
  std::vector<double> expected_d2;
  for (int trial = 0; trial < 20000; ++trial) {
    const Eigen::Vector3d p(uniform(rng), uniform(rng), 0.2 * uniform(rng));
    int expected = -1;
    double best = 9.0;
    for (std::size_t g = 0; g < planted.gaussians.size(); ++g) {
      const Eigen::Vector3d e = p - planted.gaussians[g].mean;
      const double d2 = e.dot(planted.gaussians[g].covariance.inverse() * e);
      if (d2 <= best) {
        best = d2;
        expected = int(g);
      }
    }
    points.push_back(p);
    expected_all.push_back(expected);
    expected_d2.push_back(best);
    double d2 = 0.0;
    ASSERT_EQ(index.Associate(p, 9.0, &d2), expected) << p.transpose();
    if (expected >= 0) {
      EXPECT_NEAR(d2, best, 1e-9);
      ++associated;
      // ||L^T e||^2 is the Mahalanobis^2 too, and so is MahalanobisSq.
      EXPECT_NEAR((index.SqrtInformationT(expected) * (p - index.Mean(expected))).squaredNorm(), best, 1e-9);
      EXPECT_NEAR(index.MahalanobisSq(expected, p - index.Mean(expected)), best, 1e-9);
    }
  }
  EXPECT_GT(associated, 50);
  // The information the index forms from its factor L^T is Sigma^-1.
  for (std::size_t g = 0; g < planted.gaussians.size(); ++g) {
    const Eigen::Matrix3d information = planted.gaussians[g].covariance.inverse();
    EXPECT_LT((index.Information(g) - information).norm(), 1e-10 * information.norm()) << g;
  }
  std::vector<int> batched(points.size(), -2);
  std::vector<double> batched_d2(points.size(), -1.0);
  index.AssociateAll(points.data(), points.size(), 9.0, batched.data(), batched_d2.data());
  EXPECT_EQ(batched, expected_all);
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (expected_all[k] >= 0) {
      ASSERT_NEAR(batched_d2[k], expected_d2[k], 1e-9) << k;
    }
  }
  // A non-finite point has no association, and the points around it keep theirs.
  const Eigen::Vector3d nan_point(std::nan(""), 1.0, 0.0);
  const Eigen::Vector3d inf_point(1.0, std::numeric_limits<double>::infinity(), 0.0);
  EXPECT_EQ(index.Associate(nan_point, 9.0), -1);
  EXPECT_EQ(index.Associate(inf_point, 9.0), -1);
  std::vector<Eigen::Vector3d> with_bad(points.begin(), points.begin() + 40);
  with_bad[10] = nan_point;
  with_bad[20] = inf_point;
  std::vector<int> with_bad_out(with_bad.size(), -2);
  index.AssociateAll(with_bad.data(), with_bad.size(), 9.0, with_bad_out.data());
  for (std::size_t k = 0; k < with_bad.size(); ++k) {
    EXPECT_EQ(with_bad_out[k], k == 10 || k == 20 ? -1 : expected_all[k]) << k;
  }
  // Fewer points than the batch looks ahead.
  index.AssociateAll(points.data(), 3, 9.0, batched.data());
  EXPECT_EQ(std::vector<int>(batched.begin(), batched.begin() + 3),
            std::vector<int>(expected_all.begin(), expected_all.begin() + 3));
}

// The smallest Mahalanobis^2 from `mean` over the box [lo, hi], exactly: the
// minimum of a convex quadratic over a box is where some coordinates lie on
// a face and the others minimise it given them; the least of those points
// that are in the box (27 face choices).
double SmallestMahalanobisSqOverBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Eigen::Vector3d& mean,
                                    const Eigen::Matrix3d& information) {
  double smallest = std::numeric_limits<double>::infinity();
  for (int choice = 0; choice < 27; ++choice) {
    int face[3];  // 0: free, 1: on lo, 2: on hi
    std::vector<int> free;
    Eigen::Vector3d x = mean;
    for (int i = 0, c = choice; i < 3; ++i, c /= 3) {
      face[i] = c % 3;
      if (face[i] == 0) free.push_back(i);
      if (face[i] == 1) x[i] = lo[i];
      if (face[i] == 2) x[i] = hi[i];
    }
    if (!free.empty()) {  // d/dx_f of (x - mu)^T I (x - mu) = 0 for the free coordinates
      const int n = int(free.size());
      Eigen::MatrixXd A(n, n);
      Eigen::VectorXd b(n);
      for (int r = 0; r < n; ++r) {
        b[r] = 0.0;
        for (int i = 0; i < 3; ++i) {
          if (face[i] != 0) b[r] -= information(free[r], i) * (x[i] - mean[i]);
        }
        for (int c = 0; c < n; ++c) A(r, c) = information(free[r], free[c]);
      }
      const Eigen::VectorXd offset = A.ldlt().solve(b);
      bool inside = true;
      for (int r = 0; r < n; ++r) {
        x[free[r]] = mean[free[r]] + offset[r];
        inside = inside && x[free[r]] >= lo[free[r]] && x[free[r]] <= hi[free[r]];
      }
      if (!inside) continue;
    }
    smallest = std::min(smallest, (x - mean).dot(information * (x - mean)));
  }
  return smallest;
}

// The index lists a Gaussian in exactly the cells its ellipsoid of 3 std
// meets, not in every cell of the ellipsoid's box: against the exact
// smallest Mahalanobis distance over each cell of the box, for a flat
// oblique Gaussian (most of its box is empty) and a round one (the box's
// corners are).
TEST(GaussianIndexTest, ListsAGaussianInTheCellsItsEllipsoidMeets) {
  const double cell = 0.25;
  Gaussian flat;
  flat.mean = Eigen::Vector3d(0.31, -0.22, 0.13);
  const Eigen::Matrix3d axes = SO3d::Exp(Eigen::Vector3d(0.4, 0.7, 0.2)).Matrix();
  flat.covariance = axes * Eigen::Vector3d(1.0, 0.36, 0.0025).asDiagonal() * axes.transpose();
  Gaussian round;
  round.mean = Eigen::Vector3d(-0.07, 0.11, 0.05);
  round.covariance = 0.09 * Eigen::Matrix3d::Identity();
  for (const Gaussian& g : {flat, round}) {
    const GaussianIndex index({g}, cell);
    const Eigen::Matrix3d information = g.covariance.inverse();
    const Eigen::Vector3d half = 3.0 * g.covariance.diagonal().cwiseSqrt();
    const VoxelKey lo = VoxelOf(g.mean - half, cell), hi = VoxelOf(g.mean + half, cell);
    int box_cells = 0, listed = 0;
    for (auto x = lo.x; x <= hi.x; ++x) {
      for (auto y = lo.y; y <= hi.y; ++y) {
        for (auto z = lo.z; z <= hi.z; ++z) {
          const Eigen::Vector3d corner = cell * Eigen::Vector3d(double(x), double(y), double(z));
          const double smallest = SmallestMahalanobisSqOverBox(corner, corner.array() + cell, g.mean, information);
          std::size_t count = 0;
          index.Candidates(corner.array() + 0.5 * cell, count);
          ++box_cells;
          listed += int(count);
          // Cells whose distance is within 0.1% of the extent may go either way.
          if (std::abs(smallest - 9.0) > 0.02) {
            EXPECT_EQ(count, smallest < 9.0 ? 1u : 0u) << x << " " << y << " " << z << ": " << smallest;
          }
        }
      }
    }
    EXPECT_LT(listed, 0.8 * box_cells) << listed << " of " << box_cells;
    // Points on the ellipsoid (just inside the gate) find the Gaussian in their cell.
    std::mt19937 rng(7);
    const Eigen::Matrix3d root = g.covariance.llt().matrixL();
    for (int k = 0; k < 5000; ++k) {
      const Eigen::Vector3d p = g.mean + root * (3.0 * (1.0 - 1e-12) * RandomUnitVector(rng));
      ASSERT_EQ(index.Associate(p, 9.0), 0) << p.transpose();
    }
  }
  EXPECT_THROW(GaussianIndex({flat}, cell, 0.0), std::invalid_argument);
}

// A point exactly on the gate is associated, one just beyond it is not, and
// of two equally close Gaussians the one with the smaller id wins (the
// branch-free selection keeps both rules).
// An index of the queries' cells alone (a region's fit) lists each Gaussian
// in fewer cells and answers every one of those queries as the full index:
// the same candidates, in the same order.
TEST(GaussianIndexTest, AnIndexOfTheQueriesCellsAnswersThemAsTheFullOne) {
  const Planted planted = PlantGaussians(10, 5);
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> uniform(-2.0, 20.0);
  std::vector<Eigen::Vector3d> points = planted.points;  // fewer cells than a Gaussian's box of 0.3 m cells
  for (int k = 0; k < 20; ++k) points.emplace_back(uniform(rng), uniform(rng), 0.2 * uniform(rng));
  points.emplace_back(Eigen::Vector3d::Constant(std::nan("")));  // no cell, no candidates
  const std::vector<VoxelKey> cells = GaussianIndex::CellsOf(points, 0.3);
  ASSERT_EQ(cells.size(), std::set<VoxelKey>(cells.begin(), cells.end()).size());
  std::set<VoxelKey> expected_cells;
  for (const Eigen::Vector3d& p : points) {
    if (p.allFinite()) expected_cells.insert(VoxelOf(p, 0.3));
  }
  ASSERT_EQ(std::set<VoxelKey>(cells.begin(), cells.end()), expected_cells);

  const GaussianIndex full(planted.gaussians, 0.3);
  const GaussianIndex sparse(planted.gaussians, 0.3, GaussianIndex::kExtentSigmas, &cells);
  EXPECT_LT(sparse.MemoryBytes(), full.MemoryBytes() / 2);
  int associated = 0;
  for (const Eigen::Vector3d& p : points) {
    std::size_t full_count = 0, sparse_count = 0;
    const std::uint32_t* full_candidates = full.Candidates(p, full_count);
    const std::uint32_t* sparse_candidates = sparse.Candidates(p, sparse_count);
    ASSERT_EQ(std::vector<std::uint32_t>(sparse_candidates, sparse_candidates + sparse_count),
              std::vector<std::uint32_t>(full_candidates, full_candidates + full_count))
        << p.transpose();
    EXPECT_EQ(sparse.Associate(p, 9.0), full.Associate(p, 9.0));
    associated += full.Associate(p, 9.0) >= 0;
  }
  EXPECT_GT(associated, 150);
  // Cells beyond the packing's reach would wrap: none are given.
  EXPECT_TRUE(GaussianIndex::CellsOf({Eigen::Vector3d(2e6, 0.0, 0.0)}, 1.0).empty());
  EXPECT_EQ(GaussianIndex::CellsOf({Eigen::Vector3d(-1e6, 0.0, 0.0)}, 1.0).front(), VoxelKey({-1000000, 0, 0}));
}

TEST(GaussianIndexTest, GateIsInclusiveAndTiesGoToTheSmallestId) {
  Gaussian unit;
  unit.mean.setZero();
  unit.covariance.setIdentity();  // information I: Mahalanobis^2 = |p|^2, exactly
  Gaussian far = unit;
  far.mean = Eigen::Vector3d(10.0, 0.0, 0.0);
  const GaussianIndex index({far, unit, unit}, 0.5);  // ids 1 and 2 coincide
  const std::vector<Eigen::Vector3d> points = {Eigen::Vector3d(3.0, 0.0, 0.0), Eigen::Vector3d(0.0, -3.0, 0.0),
                                               Eigen::Vector3d(0.0, 0.0, 3.0000001), Eigen::Vector3d(1.0, 2.0, 2.0)};
  const std::vector<int> expected = {1, 1, -1, 1};  // |p|^2 = 9, 9, > 9, 9
  for (std::size_t k = 0; k < points.size(); ++k) {
    double d2 = -1.0;
    EXPECT_EQ(index.Associate(points[k], 9.0, &d2), expected[k]) << k;
    if (expected[k] >= 0) {
      EXPECT_EQ(d2, 9.0) << k;
    }
  }
  std::vector<int> batched(points.size(), -2);
  index.AssociateAll(points.data(), points.size(), 9.0, batched.data());
  EXPECT_EQ(batched, expected);
  // A gate below the distance leaves every point unassociated.
  index.AssociateAll(points.data(), points.size(), 8.99, batched.data());
  EXPECT_EQ(batched, std::vector<int>(points.size(), -1));
}

TEST(GaussianIndexTest, EmptyIndexAssociatesNothing) {
  const Eigen::Vector3d p(0.1, -0.2, 0.3);
  std::size_t count = 1;
  EXPECT_EQ(GaussianIndex().Associate(p, 9.0), -1);
  EXPECT_EQ(GaussianIndex().Candidates(p, count), nullptr);
  EXPECT_EQ(count, 0u);
  EXPECT_EQ(GaussianIndex({}, 0.5).Associate(p, 9.0), -1);
  const std::vector<Eigen::Vector3d> points(20, p);
  std::vector<int> associations(points.size(), 7);
  GaussianIndex().AssociateAll(points.data(), points.size(), 9.0, associations.data());
  EXPECT_EQ(associations, std::vector<int>(points.size(), -1));
  associations.assign(points.size(), 7);
  GaussianIndex({}, 0.5).AssociateAll(points.data(), points.size(), 9.0, associations.data());
  EXPECT_EQ(associations, std::vector<int>(points.size(), -1));
}

// GroupByVoxel against a std::map of voxel keys: the packed-integer sort of
// a scan and the comparison sort of keys too far apart to pack agree with it.
TEST(GroupByVoxelTest, GroupsAsAnOrderedMapOfKeys) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> near(-60.0, 60.0);
  for (const double spread : {1.0, 1e15}) {  // 1e15 m at 0.5 m voxels: spans beyond 63 bits
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 3000; ++i) {
      const Eigen::Vector3d p(near(rng), near(rng), near(rng) / 10.0);
      points.push_back(i % 7 == 0 ? Eigen::Vector3d(spread * p) : p);
      if (i % 5 == 0) points.push_back(points.back());  // duplicates share a voxel
    }
    std::map<VoxelKey, std::vector<std::uint32_t>> reference;
    for (std::size_t i = 0; i < points.size(); ++i) reference[VoxelOf(points[i], 0.5)].push_back(std::uint32_t(i));
    std::vector<std::vector<std::uint32_t>> expected;
    for (const auto& entry : reference) expected.push_back(entry.second);
    EXPECT_EQ(GroupByVoxel(points, 0.5), expected) << "spread " << spread;
  }
  EXPECT_TRUE(GroupByVoxel({}, 0.5).empty());
  EXPECT_EQ(GroupByVoxel({Eigen::Vector3d(1, 2, 3)}, 0.5), std::vector<std::vector<std::uint32_t>>{{0}});
}

}  // namespace
}  // namespace radargauss
