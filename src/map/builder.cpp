// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/map/builder.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <queue>
#include <random>
#include <stdexcept>

#include <Eigen/LU>

#include "radargauss/map/map_file.hpp"
#include "radargauss/map/matching_map.hpp"
#include "radargauss/core/names.hpp"

namespace radargauss {

namespace {

const NamedValue<MapBuilder> kBuilderNames[] = {{MapBuilder::kKMeans, "kmeans"}, {MapBuilder::kVoxel, "voxel"}};

}  // namespace

std::string ToString(MapBuilder builder) { return NameOf(kBuilderNames, builder); }
MapBuilder MapBuilderFromString(const std::string& name) { return ValueNamed(kBuilderNames, name, "map builder"); }
std::vector<std::string> MapBuilderNames() { return NamesOf(kBuilderNames); }

namespace {

// Mean and (ML) covariance of the points listed by `members`, clamped.
Gaussian FitGaussian(const std::vector<Eigen::Vector3d>& points, const std::vector<std::uint32_t>& members,
                     double min_std) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const std::uint32_t i : members) sum += points[i];
  Gaussian g;
  g.mean = sum / double(members.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const std::uint32_t i : members) {
    const Eigen::Vector3d e = points[i] - g.mean;
    scatter += e * e.transpose();
  }
  g.covariance = ClampCovariance(scatter / double(members.size()), min_std);
  return g;
}

struct Cluster {
  std::vector<std::uint32_t> members;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double sse = 0.0;
};

void UpdateCluster(const std::vector<Eigen::Vector3d>& points, Cluster& cluster) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const std::uint32_t i : cluster.members) sum += points[i];
  cluster.mean = sum / double(cluster.members.size());
  cluster.sse = 0.0;
  for (const std::uint32_t i : cluster.members) cluster.sse += (points[i] - cluster.mean).squaredNorm();
}

// Splits `cluster` in two with 2-means (Lloyd) from two seeded members;
// false if it cannot be split (all members at one position).
bool Bisect(const std::vector<Eigen::Vector3d>& points, const Cluster& cluster, int iterations, std::mt19937& rng,
            Cluster& left, Cluster& right) {
  const std::size_t n = cluster.members.size();
  if (n < 2 || cluster.sse <= 0.0) return false;
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  Eigen::Vector3d a = points[cluster.members[pick(rng)]];
  Eigen::Vector3d b = a;
  for (int attempt = 0; attempt < 16 && (b - a).squaredNorm() == 0.0; ++attempt) {
    b = points[cluster.members[pick(rng)]];
  }
  if ((b - a).squaredNorm() == 0.0) {
    // Fall back to the member farthest from a.
    for (const std::uint32_t i : cluster.members) {
      if ((points[i] - a).squaredNorm() > (b - a).squaredNorm()) b = points[i];
    }
  }
  std::vector<char> side(n, 0);
  for (int iteration = 0; iteration < iterations; ++iteration) {
    Eigen::Vector3d sum_a = Eigen::Vector3d::Zero(), sum_b = Eigen::Vector3d::Zero();
    std::size_t count_a = 0;
    bool changed = false;
    for (std::size_t k = 0; k < n; ++k) {
      const Eigen::Vector3d& p = points[cluster.members[k]];
      const char s = (p - b).squaredNorm() < (p - a).squaredNorm() ? 1 : 0;
      changed = changed || s != side[k] || iteration == 0;
      side[k] = s;
      if (s == 0) {
        sum_a += p;
        ++count_a;
      } else {
        sum_b += p;
      }
    }
    if (count_a == 0 || count_a == n) return false;
    a = sum_a / double(count_a);
    b = sum_b / double(n - count_a);
    if (!changed) break;
  }
  left.members.clear();
  right.members.clear();
  for (std::size_t k = 0; k < n; ++k) {
    (side[k] == 0 ? left : right).members.push_back(cluster.members[k]);
  }
  if (left.members.empty() || right.members.empty()) return false;
  UpdateCluster(points, left);
  UpdateCluster(points, right);
  return true;
}

// Bisecting k-means: split the cluster of largest SSE until there are k.
std::vector<std::vector<std::uint32_t>> BisectingKMeans(const std::vector<Eigen::Vector3d>& points, std::size_t k,
                                                        const GaussianMapOptions& options,
                                                        const ProgressCallback& progress) {
  std::mt19937 rng(options.seed);
  std::vector<Cluster> clusters(1);
  clusters[0].members.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) clusters[0].members[i] = std::uint32_t(i);
  UpdateCluster(points, clusters[0]);
  // (sse, -id): largest SSE first, then the oldest cluster.
  std::priority_queue<std::pair<double, long>> queue;
  queue.push({clusters[0].sse, 0});
  std::vector<bool> final_cluster(1, false);
  std::size_t count = 1;
  while (count < k && !queue.empty()) {
    const long id = -queue.top().second;
    queue.pop();
    Cluster left, right;
    if (!Bisect(points, clusters[id], options.kmeans_iterations, rng, left, right)) continue;
    clusters[id] = std::move(left);
    clusters.push_back(std::move(right));
    queue.push({clusters[id].sse, -id});
    queue.push({clusters.back().sse, -long(clusters.size() - 1)});
    ++count;
    if (progress && count % 1024 == 0) progress("bisecting k-means", count, k);
  }
  std::vector<std::vector<std::uint32_t>> result;
  for (Cluster& cluster : clusters) result.push_back(std::move(cluster.members));
  return result;
}

// A fit of few points (a local map's region) indexes only the cells its
// points are in (GaussianIndex's `only`); a large one indexes every cell.
constexpr std::size_t kFewPoints = 4096;
constexpr std::size_t kEStepBlock = 1024;
std::vector<VoxelKey> QueryCells(const std::vector<Eigen::Vector3d>& points, double cell) {
  return points.size() <= kFewPoints ? GaussianIndex::CellsOf(points, cell) : std::vector<VoxelKey>();
}
const std::vector<VoxelKey>* QueriedOnly(const std::vector<VoxelKey>& cells) {
  return cells.empty() ? nullptr : &cells;
}

// Hard EM from an initial partition; returns the final Gaussians. Their ids
// stay fixed across the rounds (an emptied one leaves, the rest keep
// theirs), so a round refits only the Gaussians whose members changed.
std::vector<Gaussian> HardEm(const std::vector<Eigen::Vector3d>& points,
                             std::vector<std::vector<std::uint32_t>> partition, const GaussianMapOptions& options,
                             const ProgressCallback& progress) {
  std::vector<Gaussian> gaussians;
  std::vector<int> label(points.size(), -1);
  for (const auto& members : partition) {
    for (const std::uint32_t i : members) label[i] = int(gaussians.size());
    gaussians.push_back(FitGaussian(points, members, options.min_std));
  }
  std::vector<std::vector<std::uint32_t>> members = std::move(partition);  // each Gaussian's, as last fitted
  std::vector<char> alive(gaussians.size(), 1);
  const std::vector<VoxelKey> cells = QueryCells(points, options.index_cell);
  for (int iteration = 0; iteration < options.em_iterations; ++iteration) {
    // This round's index of the Gaussians left (id_of: their ids).
    std::vector<Gaussian> live;
    std::vector<std::uint32_t> id_of;
    for (std::size_t g = 0; g < gaussians.size(); ++g) {
      if (!alive[g]) continue;
      id_of.push_back(std::uint32_t(g));
      live.push_back(gaussians[g]);
    }
    const GaussianIndex index(live, options.index_cell, GaussianIndex::kExtentSigmas, QueriedOnly(cells));
    std::vector<double> half_log_det(gaussians.size());
    for (std::size_t g = 0; g < gaussians.size(); ++g) {
      if (alive[g]) half_log_det[g] = 0.5 * std::log(gaussians[g].covariance.determinant());
    }
    // E step (hard): the Gaussian of highest likelihood among the candidates,
    // in blocks of kEStepBlock points: a region's few hundred run as one,
    // with no tasks to hand out (their cost passed the fit's own).
    std::vector<int> next(points.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), kEStepBlock), [&](const auto& range) {
      for (std::size_t i = range.begin(); i < range.end(); ++i) {
        std::size_t count = 0;
        const std::uint32_t* candidates = index.Candidates(points[i], count);
        int best = label[i];
        double best_cost = INFINITY;
        for (std::size_t c = 0; c < count; ++c) {
          const std::uint32_t g = id_of[candidates[c]];
          const Eigen::Vector3d e = points[i] - index.Mean(candidates[c]);
          const double cost = 0.5 * index.MahalanobisSq(candidates[c], e) + half_log_det[g];
          if (cost < best_cost) {
            best_cost = cost;
            best = int(g);
          }
        }
        next[i] = best;
      }
    });
    const bool relabelled = next != label;
    label.swap(next);
    // M step: refit the Gaussians whose members changed; the emptied ones leave.
    std::vector<std::vector<std::uint32_t>> now(gaussians.size());
    for (std::size_t i = 0; i < points.size(); ++i) now[label[i]].push_back(std::uint32_t(i));
    for (std::size_t g = 0; g < gaussians.size(); ++g) {
      if (!alive[g] || now[g] == members[g]) continue;
      if (now[g].empty()) {
        alive[g] = 0;
      } else {
        gaussians[g] = FitGaussian(points, now[g], options.min_std);
      }
      members[g].swap(now[g]);
    }
    if (progress) progress("hard EM", std::size_t(iteration + 1), std::size_t(options.em_iterations));
    if (!relabelled) break;
  }
  std::vector<Gaussian> result;
  for (std::size_t g = 0; g < gaussians.size(); ++g) {
    if (alive[g]) result.push_back(std::move(gaussians[g]));
  }
  return result;
}

std::vector<Gaussian> VoxelGaussians(const std::vector<Eigen::Vector3d>& points, const GaussianMapOptions& options) {
  std::vector<Gaussian> gaussians;
  for (const std::vector<std::uint32_t>& members : GroupByVoxel(points, options.ndt_voxel)) {
    if (int(members.size()) >= options.ndt_min_points) {
      gaussians.push_back(FitGaussian(points, members, options.min_std));
    }
  }
  return gaussians;
}

}  // namespace

const OptionTable<GaussianMapOptions>& GaussianMapOptionTable() {
  using O = GaussianMapOptions;
  static const OptionTable<O> table = {
      RADARGAUSS_CHOICE(O, "builder", builder, MapBuilderNames(), MapBuilderFromString)
          .Help("kmeans (RA-L default) or voxel (NDT-style baseline)"),
      RADARGAUSS_OPTION(O, "downsample", downsample_voxel).Above(0.0).Unit("m").Help("voxel downsample edge"),
      RADARGAUSS_OPTION(O, "points_per_gaussian", points_per_gaussian)
          .In(1.0, 1e6)
          .Sensor()
          .Help("K = round(N_downsampled / this) (about 4 for ARS548, 16 for Oculii Eagle)"),
      RADARGAUSS_OPTION(O, "kmeans_iterations", kmeans_iterations).AtLeast(1).Help("Lloyd iterations per bisection"),
      RADARGAUSS_OPTION(O, "em_iterations", em_iterations).AtLeast(0).Help("hard-EM rounds"),
      RADARGAUSS_OPTION(O, "min_std", min_std)
          .In(kMinMapStd, kMaxMinStd)
          .Unit("m")
          .Help("minimum principal std of a Gaussian"),
      RADARGAUSS_OPTION(O, "map_seed", seed).Help("seed of the bisecting k-means"),
      RADARGAUSS_OPTION(O, "ndt_voxel", ndt_voxel).Above(0.0).Unit("m").Help("voxel edge of the voxel builder"),
      RADARGAUSS_OPTION(O, "ndt_min_points", ndt_min_points)
          .AtLeast(1)
          .Help("points a voxel of the voxel builder needs"),
      RADARGAUSS_OPTION(O, "fit_index_cell", index_cell)
          .In(kMinIndexCell, kMaxIndexCell)
          .Unit("m")
          .Help("cell of the fit's spatial index"),
      RADARGAUSS_OPTION(O, "association_gate", association_gate)
          .Above(0.0)
          .Help("members' association gate tau (Mahalanobis distance)"),
  };
  return table;
}

void ValidateOptions(const GaussianMapOptions& o) { CheckOptions(GaussianMapOptionTable(), o); }

std::vector<std::vector<std::uint32_t>> KMeansPartition(const std::vector<Eigen::Vector3d>& points, std::size_t k,
                                                        const GaussianMapOptions& options) {
  ValidateOptions(options);
  if (points.empty()) return {};
  return BisectingKMeans(points, k, options, {});
}

std::vector<int> AssociatePoints(const std::vector<Eigen::Vector3d>& points, const GaussianIndex& index, double gate) {
  std::vector<int> association(points.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 4096), [&](const auto& range) {
    index.AssociateAll(points.data() + range.begin(), range.size(), gate * gate, association.data() + range.begin());
  });
  return association;
}

std::vector<Gaussian> BuildGaussians(const std::vector<Eigen::Vector3d>& points, const GaussianMapOptions& options,
                                     const ProgressCallback& progress, std::vector<int>* association) {
  ValidateOptions(options);
  if (points.empty()) throw std::invalid_argument("cannot build a map from an empty cloud");
  std::vector<Gaussian> gaussians;
  if (options.builder == MapBuilder::kVoxel) {
    gaussians = VoxelGaussians(points, options);
  } else {
    const std::vector<Eigen::Vector3d> downsampled = VoxelDownsample(points, options.downsample_voxel);
    const std::size_t k =
        std::max<std::size_t>(1, std::size_t(std::llround(double(downsampled.size()) / options.points_per_gaussian)));
    gaussians = HardEm(downsampled, BisectingKMeans(downsampled, k, options, progress), options, progress);
  }
  // Members: every input point, associated by smallest Mahalanobis^2 within the gate.
  const std::vector<VoxelKey> cells = QueryCells(points, options.index_cell);
  const GaussianIndex index(gaussians, options.index_cell, GaussianIndex::kExtentSigmas, QueriedOnly(cells));
  std::vector<int> members = AssociatePoints(points, index, options.association_gate);
  for (const int g : members) {
    if (g >= 0) ++gaussians[g].point_count;
  }
  if (association) *association = std::move(members);
  return gaussians;
}

}  // namespace radargauss
