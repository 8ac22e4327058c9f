// SPDX-License-Identifier: BSD-3-Clause
// The world of the scan-matching benchmarks: the Gaussian-RCS map of a
// simulated 1000-scan drive (about 20k Gaussians), its matching maps, scans
// of 150, 800 and 4000 points on the same drive, the paper's initial errors
// and tracking's, and the per-scan matching loop that reports them.
#pragma once

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <type_traits>

#include "radargauss/experiment/experiment.hpp"
#include "radargauss/radargauss.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "radargauss/core/stats.hpp"

namespace radargauss {

struct MatchingWorld {
  GaussianMap map;
  std::unique_ptr<MatchingMap> matching;                        // inflated coarse levels
  std::map<int, std::unique_ptr<MatchingMap>> merged_matching;  // merged coarse levels, by coarse gate x 10
  std::map<int, SimulatedSequence> scans;                       // by detections per scan
  SimulatedSequence drive;                                      // the 1000-scan drive of the map
};

inline const MatchingWorld& World() {
  static const MatchingWorld* world = [] {
    auto* w = new MatchingWorld;
    SimulationConfig config;
    config.scans = 1000;
    w->drive = Simulate(config);
    w->map = BuildMap(AsSequence(w->drive));
    MatchingMapOptions inflated;
    inflated.coarse = CoarseLevels::kInflated;
    w->matching = std::make_unique<MatchingMap>(w->map, inflated);
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
inline std::vector<SE3d> InitialPoses(const SimulatedSequence& sequence) {
  const std::vector<SE3d> errors = InitialErrors(sequence.ground_truth.size(), 2.0, 5.0, 42);
  std::vector<SE3d> initial;
  for (std::size_t k = 0; k < errors.size(); ++k) initial.push_back(sequence.ground_truth[k].pose * errors[k]);
  return initial;
}

// Tracking's initial poses: 5 cm and 0.2 deg (yaw) off the truth, as a
// motion model would give them.
inline std::vector<SE3d> TrackingPoses(const SimulatedSequence& sequence) {
  std::vector<SE3d> initial;
  for (const auto& sample : sequence.ground_truth) {
    initial.emplace_back(sample.pose.rotation() * SO3d::Exp(Eigen::Vector3d(0, 0, 0.2 * M_PI / 180.0)),
                         sample.pose.translation() + Eigen::Vector3d(0.05, 0.0, 0.0));
  }
  return initial;
}

// Solvers by index: 0 gn, 1 gn-autodiff, 2 ceres, 3 mh-gn.
inline std::unique_ptr<ScanMatcher> Solver(int kind, const ScanMatchingOptions& options) {
  static const char* names[] = {"gn", "gn-autodiff", "ceres", "mh-gn"};
  return MakeScanMatcher(names[kind], options);
}

// Matches the scans in turn from `initial` and reports the median time the
// solver measured, iterations, convergence and the mean final errors.
inline void MatchScans(benchmark::State& state, const ScanMatcher& solver, const MatchingMap& map,
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
  state.counters["median_ms"] = Median(times);
  state.counters["converged"] = double(converged) / double(runs);
  state.counters["t_err_m"] = translation_error / double(runs);
  state.counters["r_err_deg"] = rotation_error / double(runs);
}

}  // namespace radargauss
