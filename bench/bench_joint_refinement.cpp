// SPDX-License-Identifier: BSD-3-Clause
// Joint refinement of poses and SH coefficients for 100 and 1000 scans of the
// benchmark drive.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <type_traits>

#include "bench_world.hpp"
#include "radargauss/solvers/joint_refinement.hpp"

namespace radargauss {
namespace {

// ---------------------------------------------------------------------------
// Joint refinement of n scans of the drive (poses perturbed by 0.15 m / 0.5 deg).

void BM_JointRefinement(benchmark::State& state) {
  const MatchingWorld& world = World();
  const std::size_t n = std::size_t(state.range(0));
  std::vector<RadarScan> scans;
  std::vector<SE3d> poses;
  std::mt19937 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  const std::size_t stride = world.drive.scans.size() / n;
  for (std::size_t k = 0; k < n; ++k) {
    scans.push_back(world.drive.scans[k * stride]);
    const SE3d& truth = world.drive.ground_truth[k * stride].pose;
    poses.push_back(
        k == 0 ? truth
               : SE3d(truth.rotation() * SO3d::Exp(0.005 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng))),
                      truth.translation() + 0.1 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng))));
  }
  JointRefinementOptions options;
  options.matching.w_rcs = 0.25;
  options.coefficient_prior = 1.0;
  options.threads = 2;
  options.rounds = 2;
  int iterations = 0;
  for (auto _ : state) iterations = RefineJointly(scans, poses, world.map, options).iterations;
  state.counters["ceres_iterations"] = iterations;
}
BENCHMARK(BM_JointRefinement)->Arg(100)->Arg(1000)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace radargauss

BENCHMARK_MAIN();
