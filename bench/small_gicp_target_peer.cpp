// SPDX-License-Identifier: BSD-3-Clause
// The map build against small_gicp's VGICP target on the same static cloud
// (bench/RESULTS.md, "Gaussian-RCS map"): radargauss's Gaussians (k-means +
// hard EM), the default MatchingMap and the RCS fit, against small_gicp's
// defaults (preprocess_points, RegistrationSetting): downsampling (0.25 m),
// k-d tree, covariances (10 neighbours) and Gaussian voxel map (1 m), one
// thread each. Built by scripts/small_gicp_peer.sh,
// not by CMake (small_gicp is not a Debian package).
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>

#include <small_gicp/ann/gaussian_voxelmap.hpp>
#include <small_gicp/ann/kdtree.hpp>
#include <small_gicp/points/point_cloud.hpp>
#include <small_gicp/util/downsampling.hpp>
#include <small_gicp/util/normal_estimation.hpp>

#include "radargauss/map/matching_map.hpp"
#include "radargauss/map/pipeline.hpp"

namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: small_gicp_target_peer SEQUENCE_DIR GT_TUM [points_per_gaussian=4]\n");
    return 2;
  }
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  radargauss::SequenceOptions sequence_options;
  sequence_options.sequence_dir = argv[1];
  sequence_options.ground_truth = argv[2];
  const radargauss::Sequence sequence = radargauss::LoadSequence(sequence_options);
  const radargauss::MapCloud cloud = radargauss::BuildMapCloud(sequence);
  std::printf("static cloud: %zu points\n", cloud.points.size());

  radargauss::MapOptions options;
  if (argc > 3) options.gaussians.points_per_gaussian = std::stod(argv[3]);
  auto start = std::chrono::steady_clock::now();
  const radargauss::MapGeometry geometry = radargauss::BuildMapGeometry(cloud, options);
  const double gaussians = SecondsSince(start);
  start = std::chrono::steady_clock::now();
  const radargauss::MatchingMap matching(geometry.map);
  const double matching_map = SecondsSince(start);
  start = std::chrono::steady_clock::now();
  if (cloud.has_rcs) radargauss::FitRcs(geometry, options.rcs);
  const double rcs = SecondsSince(start);
  std::printf("radargauss: %zu Gaussians %.3f s, MatchingMap %.3f s, RCS fit %.3f s, all %.3f s\n",
              geometry.map.gaussians.size(), gaussians, matching_map, rcs, gaussians + matching_map + rcs);

  start = std::chrono::steady_clock::now();
  const auto points = std::make_shared<small_gicp::PointCloud>(cloud.points);
  const auto downsampled = small_gicp::voxelgrid_sampling(*points, 0.25);
  const double downsampling = SecondsSince(start);
  start = std::chrono::steady_clock::now();
  const auto tree = std::make_shared<small_gicp::KdTree<small_gicp::PointCloud>>(downsampled);
  const double kdtree = SecondsSince(start);
  start = std::chrono::steady_clock::now();
  small_gicp::estimate_covariances(*downsampled, *tree, 10);
  const double covariances = SecondsSince(start);
  start = std::chrono::steady_clock::now();
  small_gicp::GaussianVoxelMap voxels(1.0);
  voxels.insert(*downsampled);
  const double voxelmap = SecondsSince(start);
  std::printf(
      "small_gicp: %zu points after downsampling %.3f s, k-d tree %.3f s, covariances %.3f s, "
      "voxel map %.3f s, all %.3f s\n",
      downsampled->size(), downsampling, kdtree, covariances, voxelmap, downsampling + kdtree + covariances + voxelmap);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "small_gicp_target_peer: %s\n", e.what());
  return 1;
}
