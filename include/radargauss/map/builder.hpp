// SPDX-License-Identifier: BSD-3-Clause
// Gaussian map builders (docs/design/map.md, "Gaussians").
//   kKMeans (default, the RA-L work done natively): voxel-downsample the
//     cloud (0.25 m), K = round(N_downsampled / points_per_gaussian),
//     bisecting k-means initialisation with a fixed seed, then hard EM: every
//     point to the Gaussian of highest likelihood, means and covariances
//     re-estimated, each principal std clamped to >= min_std. This minimises
//     the authors' objective (mean Mahalanobis^2 / 2 + log-scales) in closed form.
//   kVoxel (baseline, NDT/VGICP-style): one Gaussian per voxel with enough points.
// Results are the same for any thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/core/options.hpp"
#include "radargauss/core/voxel_grid.hpp"

namespace radargauss {

enum class MapBuilder { kKMeans, kVoxel };
std::string ToString(MapBuilder builder);
MapBuilder MapBuilderFromString(const std::string& name);  // "kmeans", "voxel"; throws std::invalid_argument
std::vector<std::string> MapBuilderNames();

// A Gaussian's smallest std may not pass this: the index lists a Gaussian
// in the cells of its box, which grow with the cube of its std.
constexpr double kMaxMinStd = 3.0;  // m (10 m: 9.8 GB for a 6-scan localize)

struct GaussianMapOptions {
  MapBuilder builder = MapBuilder::kKMeans;
  double downsample_voxel = 0.25;    // m (kKMeans)
  double points_per_gaussian = 4.0;  // about 4 for ARS548-like density, 16 for Oculii Eagle
  int kmeans_iterations = 8;         // Lloyd iterations per bisection
  int em_iterations = 10;            // hard-EM rounds
  double min_std = 0.05;             // m, per principal axis
  std::uint32_t seed = 1;
  double ndt_voxel = 1.0;         // m (kVoxel)
  int ndt_min_points = 5;         // (kVoxel)
  double index_cell = 1.0;        // m, voxel hash of the spatial index
  double association_gate = 3.0;  // tau: Mahalanobis distance gate for members
};

// Its options (options.hpp); ValidateOptions throws std::invalid_argument naming the bad one.
const OptionTable<GaussianMapOptions>& GaussianMapOptionTable();
void ValidateOptions(const GaussianMapOptions& options);

// Progress callback: (stage, done, total); may be empty.
using ProgressCallback = std::function<void(const char*, std::size_t, std::size_t)>;

// Means and covariances of the map of `points` (world frame). point_count of
// each Gaussian counts the members among `points` (association gated by tau);
// when `association` is given it receives that association (the Gaussian of
// each point or -1), so the RCS fit need not associate again.
// Throws std::invalid_argument for bad options or an empty cloud.
std::vector<Gaussian> BuildGaussians(const std::vector<Eigen::Vector3d>& points, const GaussianMapOptions& options,
                                     const ProgressCallback& progress = {}, std::vector<int>* association = nullptr);

// The seeding of kKMeans: `points` split by bisecting k-means (the cluster
// of largest squared error first, options.seed) into at most k clusters, as
// the members' indices of each.
std::vector<std::vector<std::uint32_t>> KMeansPartition(const std::vector<Eigen::Vector3d>& points, std::size_t k,
                                                        const GaussianMapOptions& options);

// For each point, the Gaussian it belongs to (-1: none within the gate).
std::vector<int> AssociatePoints(const std::vector<Eigen::Vector3d>& points, const GaussianIndex& index, double gate);

}  // namespace radargauss
