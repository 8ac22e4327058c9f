// SPDX-License-Identifier: BSD-3-Clause
// The pose-graph solve for 100, 1,000 and 10,000 keyframes on one core: a
// drive of laps around a 30 m circle, odometry with 5 cm / 0.01 rad noise per
// edge, a loop every fourth keyframe of each lap after the first, from the
// composed odometry; loops under graduated non-convexity (0) or DCS at
// Phi = 100 (1) from the odometry, or the same from the chordal start (2, 3).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "radargauss/solvers/pose_graph.hpp"

namespace radargauss {
namespace {

PoseGraph LapsGraph(int keyframes) {
  constexpr int kLap = 48;
  std::vector<SE3d> truth;
  for (int k = 0; k < keyframes; ++k) {
    const double a = 2.0 * M_PI * k / kLap;
    truth.emplace_back(SO3d::Exp(Eigen::Vector3d(0.0, 0.0, a)),
                       Eigen::Vector3d(30.0 * std::sin(a), 30.0 * (1.0 - std::cos(a)), 0.02 * k));
  }
  Eigen::Matrix<double, 6, 6> W = Eigen::Matrix<double, 6, 6>::Zero();
  W.diagonal() << 20.0, 20.0, 20.0, 100.0, 100.0, 100.0;
  std::mt19937 rng(1);
  std::normal_distribution<double> noise;
  PoseGraph graph;
  SE3d estimate = truth[0];
  graph.AddKeyframe(estimate);
  for (int k = 1; k < keyframes; ++k) {
    Eigen::Matrix<double, 6, 1> xi;
    for (int i = 0; i < 6; ++i) xi[i] = (i < 3 ? 0.05 : 0.01) * noise(rng);
    const SE3d measured = truth[k - 1].Inverse() * truth[k] * SE3d::Exp(xi);
    estimate = estimate * measured;
    graph.AddKeyframe(estimate);
    graph.AddOdometry(k - 1, k, measured, W);
    if (k >= kLap && k % 4 == 0) graph.AddLoop(k - kLap, k, truth[k - kLap].Inverse() * truth[k], W);
  }
  return graph;
}

void BM_PoseGraphSolve(benchmark::State& state) {
  const PoseGraph graph = LapsGraph(int(state.range(0)));
  PoseGraphOptions options;
  if (state.range(1) % 2 == 1) {
    options.loop_rejection = LoopRejection::kLoss;
    options.loop_loss = {LossType::kDcs, 10.0};
  }
  if (state.range(1) >= 2) options.initialization = GraphInitialization::kChordal;
  for (auto _ : state) {
    state.PauseTiming();
    PoseGraph copy = graph;
    state.ResumeTiming();
    const PoseGraphSummary summary = copy.Optimize(options);
    benchmark::DoNotOptimize(summary.final_cost);
    state.counters["iterations"] = summary.iterations;
    state.counters["solves"] = summary.solves;
  }
}
BENCHMARK(BM_PoseGraphSolve)
    ->ArgsProduct({{100, 1000, 10000}, {0, 1, 2, 3}})
    ->ArgNames({"keyframes", "loops"})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace radargauss

BENCHMARK_MAIN();
