// Scan matching: each residual analytic vs autodiff (with Jacobians), per-scan
// matching for 150, 800 and 4000 points at w = 0 and 0.25 for each solver
// from the paper's initial errors, multi-hypothesis with 8 starts, and joint
// refinement for 100 and 1000 scans. The map is the Gaussian-RCS map of a
// simulated 1000-scan drive (about 20k Gaussians).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <map>
#include <memory>
#include <tuple>
#include <type_traits>
#include <random>

#include "radargauss/map/builder.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/simulator.hpp"
#include "radargauss/residuals/geometric_residual.hpp"
#include "radargauss/residuals/rcs_residual.hpp"
#include "radargauss/experiment.hpp"
#include "radargauss/solvers/ceres_solver.hpp"
#include "radargauss/solvers/factory.hpp"
#include "radargauss/solvers/gauss_newton.hpp"
#include "radargauss/solvers/joint_refinement.hpp"

namespace radargauss {
namespace {

// ---------------------------------------------------------------------------
// Residuals: one evaluation with Jacobians.

struct Analytic {};
struct AutoDiff {};

// The analytic twin or the autodiff functor's cost function, from the same arguments.
template <typename Kind, typename AnalyticCost, typename Functor, typename... Args>
std::unique_ptr<ceres::CostFunction> MakeCost(const Args&... args) {
  if constexpr (std::is_same_v<Kind, Analytic>) {
    return std::make_unique<AnalyticCost>(args...);
  } else {
    return std::unique_ptr<ceres::CostFunction>(Functor::Create(args...));
  }
}

template <typename Kind>
void BM_GeometricResidual(benchmark::State& state) {
  const Eigen::Vector3d p(12.0, -3.0, 1.0), mean(11.5, -2.5, 1.2);
  const Eigen::Matrix3d LT = 10.0 * Eigen::Matrix3d::Identity();
  const auto cost = MakeCost<Kind, GeometricCostFunction, GeometricResidual>(p, mean, LT);
  Eigen::Vector4d q = SO3d::Exp(Eigen::Vector3d(0.1, -0.2, 0.3)).quaternion().coeffs();
  Eigen::Vector3d t(1.0, 2.0, 0.5);
  const double* parameters[2] = {q.data(), t.data()};
  double residuals[3], j0[12], j1[9];
  double* jacobians[2] = {j0, j1};
  for (auto _ : state) {
    cost->Evaluate(parameters, residuals, jacobians);
    benchmark::DoNotOptimize(j0[0]);
  }
}
BENCHMARK_TEMPLATE(BM_GeometricResidual, Analytic);
BENCHMARK_TEMPLATE(BM_GeometricResidual, AutoDiff);

RcsTerm BenchmarkTerm(IncidenceModel incidence) {
  RcsTerm term;
  term.point_radar = Eigen::Vector3d(12.0, -3.0, 1.0);
  term.mean = Eigen::Vector3d(11.0, -2.0, 1.5);
  term.measurement = 0.2;
  term.degree = 3;
  for (int i = 0; i < 16; ++i) term.coefficients[i] = 0.1 * (i % 5) - 0.2;
  term.incidence = incidence;
  return term;
}

template <typename Kind>
void BM_RcsResidualRotationOnly(benchmark::State& state) {
  const RcsTerm term = BenchmarkTerm(IncidenceModel(state.range(0)));
  const Eigen::Vector3d t(1.0, 2.0, 0.5);
  const auto cost = MakeCost<Kind, RcsRotationCostFunction, RcsRotationResidual>(term, t);
  Eigen::Vector4d q = SO3d::Exp(Eigen::Vector3d(0.1, -0.2, 0.3)).quaternion().coeffs();
  const double* parameters[1] = {q.data()};
  double residual, j0[4];
  double* jacobians[1] = {j0};
  for (auto _ : state) {
    cost->Evaluate(parameters, &residual, jacobians);
    benchmark::DoNotOptimize(j0[0]);
  }
  state.SetLabel(ToString(term.incidence) + ", degree 3");
}
BENCHMARK_TEMPLATE(BM_RcsResidualRotationOnly, Analytic)->Arg(0)->Arg(1);
BENCHMARK_TEMPLATE(BM_RcsResidualRotationOnly, AutoDiff)->Arg(0)->Arg(1);

// Joint refinement's RCS block: rotation-only, the 16 coefficients a block.
template <typename Kind>
void BM_RcsResidualWithCoefficients(benchmark::State& state) {
  const RcsTerm term = BenchmarkTerm(IncidenceModel::kOffset);
  const Eigen::Vector3d t(1.0, 2.0, 0.5);
  const auto cost = MakeCost<Kind, RcsCoefficientCostFunction, RcsCoefficientResidual>(term, t, false);
  Eigen::Vector4d q = SO3d::Exp(Eigen::Vector3d(0.1, -0.2, 0.3)).quaternion().coeffs();
  const double* parameters[2] = {q.data(), term.coefficients.data()};
  double residual, j0[4], j1[16];
  double* jacobians[2] = {j0, j1};
  for (auto _ : state) {
    cost->Evaluate(parameters, &residual, jacobians);
    benchmark::DoNotOptimize(j1[0]);
  }
  state.SetLabel("offset, degree 3");
}
BENCHMARK_TEMPLATE(BM_RcsResidualWithCoefficients, Analytic);
BENCHMARK_TEMPLATE(BM_RcsResidualWithCoefficients, AutoDiff);

// ---------------------------------------------------------------------------
// Per-scan matching.

struct MatchingWorld {
  GaussianMap map;
  std::unique_ptr<MatchingMap> matching;         // inflated coarse levels (the default)
  std::map<int, std::unique_ptr<MatchingMap>> merged_matching;  // merged coarse levels, by coarse gate x 10
  std::map<int, SimulatedSequence> scans;  // by detections per scan
  SimulatedSequence drive;                 // the 1000-scan drive of the map
};

const MatchingWorld& World() {
  static const MatchingWorld* world = [] {
    auto* w = new MatchingWorld;
    SimulationConfig config;
    config.scans = 1000;
    w->drive = Simulate(config);
    const MapCloud cloud = BuildMapCloud(AsSequence(w->drive));
    GaussianMapOptions options;
    std::vector<int> association;
    w->map.gaussians = BuildGaussians(cloud.points, options, {}, &association);
    FitRcsModels(w->map, cloud, association);
    w->matching = std::make_unique<MatchingMap>(w->map);
    for (const int gate_x10 : {30, 20}) {
      MatchingMapOptions merged;
      merged.coarse = CoarseLevels::kMerged;
      merged.coarse_gate = gate_x10 / 10.0;
      w->merged_matching[gate_x10] = std::make_unique<MatchingMap>(w->map, merged);
    }
    for (const int n : {150, 800, 4000}) {
      SimulationConfig scan_config;  // same seed: the same world and drive
      scan_config.scans = 20;
      scan_config.min_detections = scan_config.max_detections = n;
      scan_config.max_rays = 200000;
      w->scans[n] = Simulate(scan_config);
    }
    return w;
  }();
  return *world;
}

// The paper's protocol (experiment.hpp): translation error uniform in
// [0, 2] m, rotation uniform in [0, 5] deg, random directions; seeded.
std::vector<SE3d> InitialPoses(const SimulatedSequence& sequence) {
  const std::vector<SE3d> errors = InitialErrors(sequence.ground_truth.size(), 2.0, 5.0, 42);
  std::vector<SE3d> initial;
  for (std::size_t k = 0; k < errors.size(); ++k) initial.push_back(sequence.ground_truth[k].pose * errors[k]);
  return initial;
}

// The median of the per-scan times the solvers report.
double MedianMs(std::vector<double> times) {
  if (times.empty()) return 0.0;
  std::nth_element(times.begin(), times.begin() + times.size() / 2, times.end());
  return times[times.size() / 2];
}

std::unique_ptr<ScanMatcher> Solver(int kind, const ScanMatchingOptions& options) {
  static const char* names[] = {"gn", "gn-autodiff", "ceres", "mh-gn"};
  return MakeScanMatcher(names[kind], options);
}

// Matches the scans in turn from `initial` and reports the median time the
// solver measured, iterations, convergence and the mean final errors.
void MatchScans(benchmark::State& state, const ScanMatcher& solver, const MatchingMap& map,
                const SimulatedSequence& scans, const std::vector<SE3d>& initial, double w_rcs) {
  std::size_t k = 0, points = 0, converged = 0, runs = 0, iterations = 0, within = 0;
  double translation_error = 0.0, rotation_error = 0.0;
  std::vector<double> times;
  for (auto _ : state) {
    const ScanMatchingResult result = solver.Match(scans.scans[k], map, initial[k]);
    double t_err = 0.0, r_err_deg = 0.0;
    PoseErrors(result.pose, scans.ground_truth[k].pose, t_err, r_err_deg);
    times.push_back(result.time_ms);
    points += scans.scans[k].points.size();
    converged += result.converged;
    iterations += result.iterations;
    translation_error += t_err;
    rotation_error += r_err_deg;
    within += t_err < 0.1 && r_err_deg < 0.5;
    ++runs;
    k = (k + 1) % scans.scans.size();
  }
  state.SetLabel(solver.Name() + " w=" + std::to_string(w_rcs).substr(0, 4));
  state.counters["points"] = double(points) / double(runs);
  state.counters["iterations"] = double(iterations) / double(runs);
  state.counters["within_10cm_0.5deg"] = double(within) / double(runs);
  state.counters["median_ms"] = MedianMs(times);
  state.counters["converged"] = double(converged) / double(runs);
  state.counters["t_err_m"] = translation_error / double(runs);
  state.counters["r_err_deg"] = rotation_error / double(runs);
}

// Args: points per scan, solver (0 gn, 1 gn-autodiff, 2 ceres, 3 mh8-gn), w_rcs x 100.
void BM_MatchScan(benchmark::State& state) {
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  const MatchingWorld& world = World();
  const SimulatedSequence& scans = world.scans.at(int(state.range(0)));
  ScanMatchingOptions options;
  options.w_rcs = double(state.range(2)) / 100.0;
  MatchScans(state, *Solver(int(state.range(1)), options), *world.matching, scans, InitialPoses(scans),
             options.w_rcs);
}
BENCHMARK(BM_MatchScan)
    ->ArgsProduct({{150, 800, 4000}, {0, 1, 2}, {0, 25}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MatchScan)->Args({800, 3, 0})->Args({800, 3, 25})->Unit(benchmark::kMillisecond);

// Matches the 800-point scans on the map with merged coarse levels
// (CoarseLevels::kMerged) and the coarse gate `coarse_gate_x10` / 10 from the
// paper's errors, one thread.
void MatchScansMerged(benchmark::State& state, int solver, const ScanMatchingOptions& options,
                      int coarse_gate_x10) {
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  const MatchingWorld& world = World();
  const SimulatedSequence& scans = world.scans.at(800);
  MatchScans(state, *Solver(solver, options), *world.merged_matching.at(coarse_gate_x10), scans,
             InitialPoses(scans), options.w_rcs);
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

// Tracking's initial poses: 5 cm and 0.2 deg (yaw) off the truth, as a
// motion model would give them.
std::vector<SE3d> TrackingPoses(const SimulatedSequence& sequence) {
  std::vector<SE3d> initial;
  for (const auto& sample : sequence.ground_truth) {
    initial.emplace_back(sample.pose.rotation() * SO3d::Exp(Eigen::Vector3d(0, 0, 0.2 * M_PI / 180.0)),
                         sample.pose.translation() + Eigen::Vector3d(0.05, 0.0, 0.0));
  }
  return initial;
}

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
// (ScanMatchingOptions::loss_curvature), tracking. Arg: w_rcs x 100.
void BM_RefineScanLossCurvature(benchmark::State& state) {
  ScanMatchingOptions options;
  options.w_rcs = double(state.range(0)) / 100.0;
  options.loss_curvature = true;
  RefineScans(state, 0, options);
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
  state.counters["median_ms"] = MedianMs(times);
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
    state.counters[names[s] + "_median_ms"] = MedianMs(runs.times[s]);
    state.counters[names[s] + "_t_err_m"] = runs.t_err[s] / count;
    state.counters[names[s] + "_r_err_deg"] = runs.r_err[s] / count;
  }
}

// Ceres LM against the own GN when tracking, paired (MatchPaired): the
// medians of their per-scan times and the ratio of the medians. Args: w_rcs x 100, Ceres's blocks (0 square root, the default;
// 1 shared rows; 2 a block per term).
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
  state.SetLabel("ceres (" + std::string(block_names[state.range(1)]) + ") / gn, w=" +
                 std::to_string(options.w_rcs).substr(0, 4));
  ReportPaired(state, runs, "gn", "ceres");
  state.counters["ratio"] = MedianMs(runs.times[1]) / MedianMs(runs.times[0]);
}
BENCHMARK(BM_RefineScanCeresOverGn)->ArgsProduct({{0, 25}, {0, 1, 2}})->Unit(benchmark::kMillisecond);

// Ceres LM (default blocks) against the own GN from the paper's errors
// (2 m / 5 deg), paired (MatchPaired): medians, their ratio and the mean
// final errors. Args: w_rcs x 100, levels (1 merged with gate 3, 2 the
// default inflated).
void BM_MatchScanCeresOverGn(benchmark::State& state) {
  const Tracking tracking;
  const MatchingWorld& world = tracking.world;
  const bool merged = state.range(1) == 1;
  const MatchingMap& map = merged ? *world.merged_matching.at(30) : *world.matching;
  ScanMatchingOptions options;
  options.w_rcs = double(state.range(0)) / 100.0;
  const PairedRuns runs = MatchPaired(state, *Solver(0, options), *Solver(2, options), map, tracking.scans,
                                      InitialPoses(tracking.scans));
  state.SetLabel(std::string("ceres / gn, ") + (merged ? "merged" : "inflated") +
                 ", w=" + std::to_string(options.w_rcs).substr(0, 4));
  ReportPaired(state, runs, "gn", "ceres");
  state.counters["ratio"] = MedianMs(runs.times[1]) / MedianMs(runs.times[0]);
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
  state.counters["ratio"] = MedianMs(runs.times[0]) / MedianMs(runs.times[1]);
}
BENCHMARK(BM_GeometricFirstOverThroughout)->ArgsProduct({{0, 2}, {0, 1, 2}})->Unit(benchmark::kMillisecond);

// The parts of one outer iteration on the exact map, 800 points at the
// reference pose: association (FindCorrespondences) and the normal equations
// (BuildGeometricSystem, BuildRcsSystem; analytic and autodiff).
void BM_AssociateScan(benchmark::State& state) {
  const MatchingWorld& world = World();
  const SimulatedSequence& scans = world.scans.at(800);
  const bool with_rcs = state.range(0) != 0;
  std::size_t k = 0, points = 0;
  for (auto _ : state) {
    const Correspondences c = FindCorrespondences(scans.scans[k], *world.matching, world.matching->levels() - 1,
                                                  scans.ground_truth[k].pose, 3.0, with_rcs);
    benchmark::DoNotOptimize(c.geometric.data());
    points += scans.scans[k].points.size();
    k = (k + 1) % scans.scans.size();
  }
  state.counters["per_point"] =
      benchmark::Counter(double(points), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.SetLabel(with_rcs ? "geometric + RCS terms" : "geometric terms");
}
BENCHMARK(BM_AssociateScan)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_BuildSystem(benchmark::State& state) {
  const MatchingWorld& world = World();
  const SimulatedSequence& scans = world.scans.at(800);
  std::vector<Correspondences> correspondences;
  for (std::size_t k = 0; k < scans.scans.size(); ++k) {
    correspondences.push_back(FindCorrespondences(scans.scans[k], *world.matching, world.matching->levels() - 1,
                                                  scans.ground_truth[k].pose, 3.0, true));
  }
  ScanMatchingOptions options;
  options.jacobians = state.range(0) == 0 ? JacobianMode::kAnalytic : JacobianMode::kAutoDiff;
  std::size_t k = 0, terms = 0;
  for (auto _ : state) {
    const LinearSystem system = state.range(1) == 0
                                    ? BuildGeometricSystem(correspondences[k], scans.ground_truth[k].pose, options)
                                    : BuildRcsSystem(correspondences[k], scans.ground_truth[k].pose, options);
    benchmark::DoNotOptimize(system.H.data());
    terms += system.residuals;
    k = (k + 1) % correspondences.size();
  }
  state.counters["per_term"] =
      benchmark::Counter(double(terms), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.SetLabel(std::string(state.range(1) == 0 ? "geometric" : "RCS") +
                 (state.range(0) == 0 ? ", analytic" : ", autodiff"));
}
BENCHMARK(BM_BuildSystem)->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMicrosecond);

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
    poses.push_back(k == 0 ? truth
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
