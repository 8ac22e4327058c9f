// SPDX-License-Identifier: BSD-3-Clause
// The Gaussian builders and voxel downsampling, on planted Gaussians.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>

#include "radargauss/core/error.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "support/temp_dir.hpp"
#include "support/map_fixtures.hpp"

namespace radargauss {
namespace {

using testing::RandomUnitVector;

// Voxel downsampling: the centroid of each occupied voxel (by hand), in key
// order or in the order of each voxel's first point, non-finite points
// skipped; many random clouds give the same centroids in both orders.
TEST(VoxelDownsample, CentroidsPerVoxelInEitherOrder) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Eigen::Vector3d> points = {{1.2, 0.1, 0.1}, {-0.5, 0.5, 0.5}, {1.6, 0.3, 0.9},
                                               {nan, 0.0, 0.0}, {-0.7, 0.1, 0.3}, {0.5, 0.5, 0.5}};
  // Voxels of 1 m: (1,0,0) first, then (-1,0,0), then (0,0,0).
  const std::vector<Eigen::Vector3d> by_first = {{1.4, 0.2, 0.5}, {-0.6, 0.3, 0.4}, {0.5, 0.5, 0.5}};
  const std::vector<Eigen::Vector3d> first = VoxelDownsample(points, 1.0, VoxelOrder::kFirstPoint);
  const std::vector<Eigen::Vector3d> keyed = VoxelDownsample(points, 1.0);
  ASSERT_EQ(first.size(), 3u);
  ASSERT_EQ(keyed.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_LT((first[k] - by_first[k]).norm(), 1e-12) << k;
  EXPECT_LT((keyed[0] - by_first[1]).norm(), 1e-12);  // x = -1, 0, 1
  EXPECT_LT((keyed[1] - by_first[2]).norm(), 1e-12);
  EXPECT_LT((keyed[2] - by_first[0]).norm(), 1e-12);
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 5.0);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Eigen::Vector3d> cloud(1 + rng() % 3000);
    for (Eigen::Vector3d& p : cloud) p = {normal(rng), normal(rng), 0.2 * normal(rng)};
    const double voxel = 0.1 + 0.2 * trial;
    const auto less = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
      return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
    };
    std::vector<Eigen::Vector3d> a = VoxelDownsample(cloud, voxel, VoxelOrder::kFirstPoint);
    std::vector<Eigen::Vector3d> b = VoxelDownsample(cloud, voxel);
    for (std::size_t k = 1; k < b.size(); ++k) {
      EXPECT_TRUE(VoxelOf(b[k - 1], voxel) < VoxelOf(b[k], voxel)) << "trial " << trial;
    }
    std::sort(a.begin(), a.end(), less);
    std::sort(b.begin(), b.end(), less);
    EXPECT_EQ(a, b) << "trial " << trial;
  }
  EXPECT_TRUE(VoxelDownsample({}, 1.0).empty());
}

TEST(GaussianBuilder, RecoversPlantedGaussians) {
  const Planted planted = PlantGaussians(2000, 1);
  GaussianMapOptions options;
  options.downsample_voxel = 0.02;
  // K from the density, as the method sets it: here so that K = 16.
  const std::size_t downsampled = VoxelDownsample(planted.points, options.downsample_voxel).size();
  options.points_per_gaussian = double(downsampled) / planted.gaussians.size();
  options.em_iterations = 20;
  const std::vector<Gaussian> built = BuildGaussians(planted.points, options);
  ASSERT_EQ(built.size(), planted.gaussians.size());
  for (const Gaussian& p : planted.gaussians) {
    const Gaussian* nearest = &built[0];
    for (const Gaussian& b : built) {
      if ((b.mean - p.mean).norm() < (nearest->mean - p.mean).norm()) nearest = &b;
    }
    EXPECT_LT((nearest->mean - p.mean).norm(), 0.1) << p.mean.transpose();
    EXPECT_LT((nearest->covariance - p.covariance).norm(), 0.15 * p.covariance.norm()) << "planted\n"
                                                                                       << p.covariance << "\nbuilt\n"
                                                                                       << nearest->covariance;
    EXPECT_GT(nearest->point_count, 1900u);  // members within tau = 3 of 2000 samples
  }
}

TEST(GaussianBuilder, SameResultForAnyThreadCount) {
  const Planted planted = PlantGaussians(500, 2);
  GaussianMapOptions options;
  std::vector<Gaussian> one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = BuildGaussians(planted.points, options);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = BuildGaussians(planted.points, options);
  }
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].mean, two[i].mean);
    EXPECT_EQ(one[i].covariance, two[i].covariance);
    EXPECT_EQ(one[i].point_count, two[i].point_count);
  }
}

TEST(GaussianBuilder, ClampsStdAndVoxelBaseline) {
  // Points on a plane: the normal std is clamped to min_std.
  std::vector<Eigen::Vector3d> plane;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) plane.emplace_back(0.05 * i, 0.05 * j, 0.0);
  }
  GaussianMapOptions options;
  options.builder = MapBuilder::kVoxel;
  options.ndt_voxel = 1.0;
  const std::vector<Gaussian> voxel = BuildGaussians(plane, options);
  ASSERT_EQ(voxel.size(), 4u);  // 2 m x 2 m of plane in 1 m voxels
  for (const Gaussian& g : voxel) {
    Eigen::Vector3d stds;
    Eigen::Matrix3d axes;
    PrincipalAxes(g.covariance, stds, axes);
    EXPECT_NEAR(stds[0], options.min_std, 1e-12);
    EXPECT_EQ(g.point_count, 400u);
  }
  EXPECT_THROW(BuildGaussians({}, options), std::invalid_argument);
  options.min_std = 0.0;
  EXPECT_THROW(BuildGaussians(plane, options), std::invalid_argument);
}

}  // namespace
}  // namespace radargauss
