// SPDX-License-Identifier: BSD-3-Clause
// Map building: the whole map + RCS fit for 100k and 1M map points, the
// association of one point, the RCS fit of one Gaussian, and the memory of
// a Gaussian (map entry + spatial index).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <random>
#include <vector>

#include "radargauss/map/pipeline.hpp"
#include "radargauss/solvers/correspondences.hpp"

namespace radargauss {
namespace {

// A town-like map cloud: points on random vertical walls (10 m x 5 m, 5 cm
// noise) seen from poses along a line, with RCS values. Deterministic.
MapCloud TownCloud(std::size_t n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  const std::size_t walls = std::max<std::size_t>(1, n / 2500);  // ~50 points per m^2
  std::vector<Eigen::Vector3d> origin(walls), along(walls);
  for (std::size_t w = 0; w < walls; ++w) {
    origin[w] = Eigen::Vector3d(600.0 * unit(rng), 600.0 * unit(rng), 0.0);
    const double yaw = 2.0 * M_PI * unit(rng);
    along[w] = Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0);
  }
  MapCloud cloud;
  cloud.has_rcs = true;
  for (int k = 0; k < 1000; ++k) {
    cloud.poses.emplace_back(SO3d(), Eigen::Vector3d(0.6 * k, 300.0, 1.0));
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t w = i % walls;
    const Eigen::Vector3d normal(-along[w].y(), along[w].x(), 0.0);
    cloud.points.push_back(origin[w] + 10.0 * unit(rng) * along[w] + Eigen::Vector3d(0, 0, 5.0 * unit(rng)) +
                           noise(rng) * normal);
    cloud.rcs.push_back(5.0 + 3.0 * std::sin(7.0 * unit(rng)) + noise(rng) * 20.0);
    cloud.scan.push_back(std::uint32_t(rng() % cloud.poses.size()));
  }
  return cloud;
}

// The build-map pipeline after the Doppler filter: Gaussians, members, RCS models.
void BM_BuildMapAndRcs(benchmark::State& state) {
  const MapCloud cloud = TownCloud(std::size_t(state.range(0)));
  std::size_t gaussians = 0;
  for (auto _ : state) gaussians = FitRcs(BuildMapGeometry(cloud)).gaussians.size();
  state.counters["gaussians"] = double(gaussians);
}
BENCHMARK(BM_BuildMapAndRcs)->Arg(100000)->Arg(1000000)->Unit(benchmark::kSecond)->Iterations(1);

struct BuiltMap {
  MapCloud cloud;
  GaussianMap map;
  GaussianIndex index;
};

const BuiltMap& Built() {
  static const BuiltMap built = [] {
    BuiltMap b;
    b.cloud = TownCloud(100000);
    b.map.gaussians = BuildGaussians(b.cloud.points, GaussianMapOptions{});
    b.index = GaussianIndex(b.map.gaussians, 1.0);
    return b;
  }();
  return built;
}

void BM_AssociatePoint(benchmark::State& state) {
  const BuiltMap& b = Built();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(b.index.Associate(b.cloud.points[i], 9.0));
    i = (i + 7919) % b.cloud.points.size();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_AssociatePoint);

// The same queries batched (GaussianIndex::AssociateAll, memory fetched
// ahead), 800 at a time as a scan: time per point.
void BM_AssociatePointsBatched(benchmark::State& state) {
  const BuiltMap& b = Built();
  constexpr std::size_t kBatch = 800;
  std::vector<Eigen::Vector3d> points;
  for (std::size_t k = 0, i = 0; k < 100 * kBatch; ++k, i = (i + 7919) % b.cloud.points.size()) {
    points.push_back(b.cloud.points[i]);
  }
  std::vector<int> associations(kBatch);
  std::size_t batch = 0;
  for (auto _ : state) {
    b.index.AssociateAll(points.data() + batch * kBatch, kBatch, 9.0, associations.data());
    benchmark::DoNotOptimize(associations.data());
    batch = (batch + 1) % 100;
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}
BENCHMARK(BM_AssociatePointsBatched);

// A scan of 3000 points associated against the map (AssociateScan: blocks
// of 256 points side by side), on 1 and 2 threads: time per scan.
void BM_AssociateScan(benchmark::State& state) {
  const BuiltMap& b = Built();
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(state.range(0)));
  RadarScan scan;
  for (std::size_t k = 0, i = 0; k < 3000; ++k, i = (i + 7919) % b.cloud.points.size()) {
    RadarPoint point;
    point.position = b.cloud.points[i];
    scan.points.push_back(point);
  }
  for (auto _ : state) benchmark::DoNotOptimize(AssociateScan(scan, b.index, SE3d(), 3.0).data());
  state.SetItemsProcessed(state.iterations() * std::int64_t(scan.points.size()));
}
BENCHMARK(BM_AssociateScan)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond)->UseRealTime();

// One region's refit in the local map: build-map's estimator on 256 points
// (a region's capacity) in a 4 m cube, its E steps on an index of the
// points' cells alone.
void BM_FitRegion(benchmark::State& state) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(0.0, 4.0);
  std::normal_distribution<double> normal(0.0, 0.05);
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < 256; ++k) {  // two walls and a floor
    const double u = uniform(rng), v = uniform(rng);
    points.emplace_back(k % 3 == 0
                            ? Eigen::Vector3d(u, v, normal(rng))
                            : (k % 3 == 1 ? Eigen::Vector3d(u, normal(rng), v) : Eigen::Vector3d(normal(rng), u, v)));
  }
  GaussianMapOptions options;
  options.points_per_gaussian = double(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(BuildGaussians(points, options).size());
}
BENCHMARK(BM_FitRegion)->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);

void BM_FitRcsModelDegree3(benchmark::State& state) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  std::vector<Eigen::Vector3d> directions;
  std::vector<double> rcs;
  for (int i = 0; i < state.range(0); ++i) {
    Eigen::Vector3d d(normal(rng), normal(rng), normal(rng));
    d.normalize();
    if (d.x() > 0) d = -d;
    directions.push_back(d);
    rcs.push_back(normal(rng));
  }
  for (auto _ : state) benchmark::DoNotOptimize(FitRcsModel(directions, rcs).coefficients[0]);
}
BENCHMARK(BM_FitRcsModelDegree3)->Arg(20)->Arg(100)->Unit(benchmark::kMicrosecond);

// Bytes per Gaussian in memory: the map entry plus its share of the index.
void BM_BytesPerGaussian(benchmark::State& state) {
  const BuiltMap& b = Built();
  for (auto _ : state) benchmark::DoNotOptimize(b.index.MemoryBytes());
  const double n = double(b.map.gaussians.size());
  state.counters["map_bytes_per_gaussian"] = double(sizeof(Gaussian));
  state.counters["index_bytes_per_gaussian"] = double(b.index.MemoryBytes()) / n;
}
BENCHMARK(BM_BytesPerGaussian)->Iterations(1);

}  // namespace
}  // namespace radargauss

BENCHMARK_MAIN();
