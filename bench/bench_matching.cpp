// SPDX-License-Identifier: BSD-3-Clause
// Per-scan matching, one thread: every solver from the paper's initial errors
// (150, 800 and 4000 points, w = 0 and 0.25), merged coarse levels and their
// settings, tracking (refinement from 5 cm / 0.2 deg) and its settings, and
// paired runs of Ceres against the own Gauss-Newton.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <type_traits>

#include "bench_world.hpp"
#include "radargauss/solvers/ceres_solver.hpp"
#include "radargauss/solvers/gauss_newton.hpp"

namespace radargauss {
namespace {

// Args: points per scan, solver (0 gn, 1 gn-autodiff, 2 ceres, 3 mh8-gn), w_rcs x 100.
void BM_MatchScan(benchmark::State& state) {
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  const MatchingWorld& world = World();
  const SimulatedSequence& scans = world.scans.at(int(state.range(0)));
  ScanMatchingOptions options;
  options.w_rcs = double(state.range(2)) / 100.0;
  MatchScans(state, *Solver(int(state.range(1)), options), *world.matching, scans, InitialPoses(scans), options.w_rcs);
}
BENCHMARK(BM_MatchScan)->ArgsProduct({{150, 800, 4000}, {0, 1, 2}, {0, 25}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MatchScan)->Args({800, 3, 0})->Args({800, 3, 25})->Unit(benchmark::kMillisecond);

// Matches the 800-point scans on the map with merged coarse levels
// (CoarseLevels::kMerged) and the coarse gate `coarse_gate_x10` / 10 from the
// paper's errors, one thread.
void MatchScansMerged(benchmark::State& state, int solver, const ScanMatchingOptions& options, int coarse_gate_x10) {
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  const MatchingWorld& world = World();
  const SimulatedSequence& scans = world.scans.at(800);
  MatchScans(state, *Solver(solver, options), *world.merged_matching.at(coarse_gate_x10), scans, InitialPoses(scans),
             options.w_rcs);
}

// Args: solver (0 gn, 2 ceres), w_rcs x 100, coarse_points, coarse gate x 10,
// coarse voxel per sigma x 10 (0: the scan's points).
void BM_MatchScanMerged(benchmark::State& state) {
  ScanMatchingOptions options;
  options.w_rcs = double(state.range(1)) / 100.0;
  options.coarse_points = std::size_t(state.range(2));
  options.coarse_voxel_per_sigma = double(state.range(4)) / 10.0;
  MatchScansMerged(state, int(state.range(0)), options, int(state.range(3)));
}
BENCHMARK(BM_MatchScanMerged)
    ->ArgsProduct({{0, 2}, {0, 25}, {0, 400}, {30, 20}, {0, 20}})
    ->Unit(benchmark::kMillisecond);

// How much of BM_MatchScanMerged the coarse levels take: the same matches
// (own GN), stopped after the exact map's first iteration. Args: w_rcs x 100
// (the coarse levels are geometric only; w enters that one iteration),
// coarse_points, coarse gate x 10, coarse voxel per sigma x 10.
void BM_MatchScanMergedCoarseLevels(benchmark::State& state) {
  ScanMatchingOptions options;
  options.w_rcs = double(state.range(0)) / 100.0;
  options.coarse_points = std::size_t(state.range(1));
  options.coarse_voxel_per_sigma = double(state.range(3)) / 10.0;
  options.max_iterations = 1;
  MatchScansMerged(state, 0, options, int(state.range(2)));
}
BENCHMARK(BM_MatchScanMergedCoarseLevels)
    ->ArgsProduct({{0, 25}, {0, 400}, {30, 20}, {0, 20}})
    ->Unit(benchmark::kMillisecond);

// What every tracking benchmark matches: 800-point scans on the exact map
// (no coarse levels) from 5 cm / 0.2 deg, one thread.
struct Tracking {
  const tbb::global_control one_thread{tbb::global_control::max_allowed_parallelism, 1};
  const MatchingWorld& world = World();
  const MatchingMap exact{world.map, ExactMapOnly()};
  const SimulatedSequence& scans = world.scans.at(800);
  const std::vector<SE3d> initial = TrackingPoses(scans);
};

// Refinement only: the per-scan latency of tracking.
void RefineScans(benchmark::State& state, int solver, const ScanMatchingOptions& options) {
  const Tracking tracking;
  MatchScans(state, *Solver(solver, options), tracking.exact, tracking.scans, tracking.initial, options.w_rcs);
}

// Args: solver, w_rcs x 100.
void BM_RefineScan(benchmark::State& state) {
  ScanMatchingOptions options;
  options.w_rcs = double(state.range(1)) / 100.0;
  RefineScans(state, int(state.range(0)), options);
}
BENCHMARK(BM_RefineScan)->ArgsProduct({{0, 1, 2}, {0, 25}})->Unit(benchmark::kMillisecond);

// The own GN with the losses' curvature in its Hessian
// (GaussNewtonOptions::loss_curvature), tracking. Arg: w_rcs x 100.
void BM_RefineScanLossCurvature(benchmark::State& state) {
  ScanMatchingOptions options;
  options.w_rcs = double(state.range(0)) / 100.0;
  const Tracking tracking;
  MatchScans(state, GaussNewtonSolver(options, {8, true}), tracking.exact, tracking.scans, tracking.initial,
             options.w_rcs);
}
BENCHMARK(BM_RefineScanLossCurvature)->Arg(0)->Arg(25)->Unit(benchmark::kMillisecond);

// The own GN when tracking under other stopping and re-association settings
// than the defaults: what they buy in latency and what they cost against the
// defaults' answer. Counters t_dev_m / r_dev_deg: mean distance of each
// scan's result from the default settings' result on the same scan.
// Args: w_rcs x 100, setting (0 defaults; 1 eager re-association, after
// every step; 2 steps to 0.1 mm / 1e-5 rad; 3 re-association after 2 cm instead of 1 cm; 4 small_gicp's step
// tolerances, 1 mm / 0.1 deg; 5 re-association after 3 cm / 0.006 rad,
// beyond this benchmark's initial error: one association per match).
void BM_RefineScanSettings(benchmark::State& state) {
  const Tracking tracking;
  const auto& [exact, scans, initial] = std::tie(tracking.exact, tracking.scans, tracking.initial);
  ScanMatchingOptions defaults;
  defaults.w_rcs = double(state.range(0)) / 100.0;
  ScanMatchingOptions options = defaults;
  const int setting = int(state.range(1));
  if (setting == 1) options.reassociation_translation = options.reassociation_rotation = 0.0;
  if (setting == 2) {
    options.translation_tolerance = 1e-4;
    options.rotation_tolerance = 1e-5;
  }
  if (setting == 3) options.reassociation_translation = 0.02;
  if (setting == 4) options.rotation_tolerance = 0.1 * M_PI / 180.0;
  if (setting == 5) {
    options.reassociation_translation = 0.03;
    options.reassociation_rotation = 0.006;
  }
  std::vector<SE3d> reference;
  const GaussNewtonSolver default_solver(defaults);
  for (std::size_t k = 0; k < scans.scans.size(); ++k) {
    reference.push_back(default_solver.Match(scans.scans[k], exact, initial[k]).pose);
  }
  const GaussNewtonSolver solver(options);
  std::vector<double> times;
  double t_dev = 0.0, r_dev = 0.0, t_err = 0.0, r_err = 0.0, iterations = 0.0;
  std::size_t k = 0;
  for (auto _ : state) {
    const ScanMatchingResult result = solver.Match(scans.scans[k], exact, initial[k]);
    times.push_back(result.time_ms);
    double dt = 0.0, dr = 0.0;
    PoseErrors(result.pose, reference[k], dt, dr);
    t_dev += dt;
    r_dev += dr;
    PoseErrors(result.pose, scans.ground_truth[k].pose, dt, dr);
    t_err += dt;
    r_err += dr;
    iterations += result.iterations;
    k = (k + 1) % scans.scans.size();
  }
  const double runs = double(times.size());
  state.SetLabel("gn setting " + std::to_string(setting) + " w=" + std::to_string(defaults.w_rcs).substr(0, 4));
  state.counters["median_ms"] = Median(times);
  state.counters["iterations"] = iterations / runs;
  state.counters["t_dev_m"] = t_dev / runs;
  state.counters["r_dev_deg"] = r_dev / runs;
  state.counters["t_err_m"] = t_err / runs;
  state.counters["r_err_deg"] = r_err / runs;
}
BENCHMARK(BM_RefineScanSettings)->ArgsProduct({{0, 25}, {0, 1, 2, 3, 4, 5}})->Unit(benchmark::kMillisecond);

// Two solvers on the same matches, interleaved scan by scan (this shared
// machine's load drifts over both alike) and taking turns at going first
// (the second would run on the caches the first warmed for that scan: up to
// 20% faster on the same match). Per solver: its per-scan times and the sums
// of its final errors against the truth.
struct PairedRuns {
  std::vector<double> times[2];
  double t_err[2] = {0.0, 0.0}, r_err[2] = {0.0, 0.0};
};
PairedRuns MatchPaired(benchmark::State& state, const ScanMatcher& a, const ScanMatcher& b, const MatchingMap& map,
                       const SimulatedSequence& scans, const std::vector<SE3d>& initial) {
  const ScanMatcher* solvers[2] = {&a, &b};
  PairedRuns runs;
  std::size_t k = 0, pass = 0;
  for (auto _ : state) {
    for (int i = 0; i < 2; ++i) {
      const int s = int((i + k + pass) % 2);  // on each scan, a and b take turns pass by pass
      const ScanMatchingResult result = solvers[s]->Match(scans.scans[k], map, initial[k]);
      runs.times[s].push_back(result.time_ms);
      double dt = 0.0, dr = 0.0;
      PoseErrors(result.pose, scans.ground_truth[k].pose, dt, dr);
      runs.t_err[s] += dt;
      runs.r_err[s] += dr;
    }
    if (++k == scans.scans.size()) {
      k = 0;
      ++pass;
    }
  }
  return runs;
}

// The counters of paired runs: per solver (named `a` and `b`) its median
// time per scan and its mean final errors.
void ReportPaired(benchmark::State& state, const PairedRuns& runs, const std::string& a, const std::string& b) {
  const double count = double(runs.times[0].size());
  const std::string names[2] = {a, b};
  for (int s = 0; s < 2; ++s) {
    state.counters[names[s] + "_median_ms"] = Median(runs.times[s]);
    state.counters[names[s] + "_t_err_m"] = runs.t_err[s] / count;
    state.counters[names[s] + "_r_err_deg"] = runs.r_err[s] / count;
  }
}

// Ceres LM against the own GN when tracking, paired (MatchPaired): the
// medians of their per-scan times and the ratio of the medians. Args: w_rcs x 100, Ceres's blocks (0 square root, the
// default; 1 shared rows; 2 a block per term).
void BM_RefineScanCeresOverGn(benchmark::State& state) {
  const Tracking tracking;
  ScanMatchingOptions options;
  options.w_rcs = double(state.range(0)) / 100.0;
  static const CeresBlocks blocks[] = {CeresBlocks::kSquareRoot, CeresBlocks::kShared, CeresBlocks::kPerTerm};
  static const char* block_names[] = {"square root", "shared rows", "a block per term"};
  CeresSolverOptions ceres_options;
  ceres_options.blocks = blocks[state.range(1)];
  const CeresSolver ceres(options, ceres_options);
  const PairedRuns runs =
      MatchPaired(state, *Solver(0, options), ceres, tracking.exact, tracking.scans, tracking.initial);
  state.SetLabel("ceres (" + std::string(block_names[state.range(1)]) +
                 ") / gn, w=" + std::to_string(options.w_rcs).substr(0, 4));
  ReportPaired(state, runs, "gn", "ceres");
  state.counters["ratio"] = Median(runs.times[1]) / Median(runs.times[0]);
}
BENCHMARK(BM_RefineScanCeresOverGn)->ArgsProduct({{0, 25}, {0, 1, 2}})->Unit(benchmark::kMillisecond);

// Ceres LM (default blocks) against the own GN from the paper's errors
// (2 m / 5 deg), paired (MatchPaired): medians, their ratio and the mean
// final errors. Args: w_rcs x 100, levels (1 merged with gate 3, the
// default; 2 inflated).
void BM_MatchScanCeresOverGn(benchmark::State& state) {
  const Tracking tracking;
  const MatchingWorld& world = tracking.world;
  const bool merged = state.range(1) == 1;
  const MatchingMap& map = merged ? *world.merged_matching.at(30) : *world.matching;
  ScanMatchingOptions options;
  options.w_rcs = double(state.range(0)) / 100.0;
  const PairedRuns runs =
      MatchPaired(state, *Solver(0, options), *Solver(2, options), map, tracking.scans, InitialPoses(tracking.scans));
  state.SetLabel(std::string("ceres / gn, ") + (merged ? "merged" : "inflated") +
                 ", w=" + std::to_string(options.w_rcs).substr(0, 4));
  ReportPaired(state, runs, "gn", "ceres");
  state.counters["ratio"] = Median(runs.times[1]) / Median(runs.times[0]);
}
BENCHMARK(BM_MatchScanCeresOverGn)->ArgsProduct({{0, 25}, {1, 2}})->Unit(benchmark::kMillisecond);

// geometric_first against eq. 2 throughout on the exact map, w = 0.25,
// paired (MatchPaired): the medians of their per-scan times, their ratio and
// their mean final errors. Args: solver (0 gn, 2 ceres), start (0 tracking
// on the exact map; from the paper's errors 1 merged coarse levels, 2 inflated).
void BM_GeometricFirstOverThroughout(benchmark::State& state) {
  const Tracking tracking;
  const MatchingWorld& world = tracking.world;
  const int start = int(state.range(1));
  const MatchingMap& map = start == 0 ? tracking.exact : start == 1 ? *world.merged_matching.at(30) : *world.matching;
  const std::vector<SE3d> initial = start == 0 ? tracking.initial : InitialPoses(tracking.scans);
  ScanMatchingOptions first;
  first.w_rcs = 0.25;
  ScanMatchingOptions throughout = first;
  throughout.geometric_first = false;
  const std::unique_ptr<ScanMatcher> solver = Solver(int(state.range(0)), first);
  const PairedRuns runs =
      MatchPaired(state, *solver, *Solver(int(state.range(0)), throughout), map, tracking.scans, initial);
  state.SetLabel(solver->Name() + (start == 0 ? " tracking" : start == 1 ? " merged" : " inflated"));
  ReportPaired(state, runs, "first", "throughout");
  state.counters["ratio"] = Median(runs.times[0]) / Median(runs.times[1]);
}
BENCHMARK(BM_GeometricFirstOverThroughout)->ArgsProduct({{0, 2}, {0, 1, 2}})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace radargauss

BENCHMARK_MAIN();
