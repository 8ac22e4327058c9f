// SPDX-License-Identifier: BSD-3-Clause
// Core building blocks: SH basis evaluation per degree (double and Jet, as in
// the autodiff RCS residual) and SE3 Exp / Log / point action.
#include <benchmark/benchmark.h>
#include <ceres/jet.h>

#include <random>
#include <vector>

#include "radargauss/lie/se3.hpp"
#include "radargauss/core/sh.hpp"

namespace radargauss {
namespace {

constexpr int kBatch = 1024;  // inputs cycled through, so the compiler cannot fold them

std::vector<Eigen::Vector3d> RandomDirections() {
  std::mt19937 rng(1);
  std::normal_distribution<double> normal;
  std::vector<Eigen::Vector3d> directions(kBatch);
  for (auto& d : directions) d = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  return directions;
}

template <int Degree>
void BM_ShBasisDouble(benchmark::State& state) {
  const auto directions = RandomDirections();
  double basis[ShCoefficientCount(Degree)];
  std::size_t i = 0;
  for (auto _ : state) {
    EvaluateShBasis<Degree>(directions[i++ % kBatch], basis);
    benchmark::DoNotOptimize(basis);
  }
  state.SetItemsProcessed(state.iterations());
}

// Jet with 4 derivatives: the rotation block of the autodiff RCS residual.
template <int Degree>
void BM_ShBasisJet(benchmark::State& state) {
  using Jet = ceres::Jet<double, 4>;
  const auto directions = RandomDirections();
  std::vector<Eigen::Matrix<Jet, 3, 1>> jets(kBatch);
  for (int k = 0; k < kBatch; ++k) {
    for (int j = 0; j < 3; ++j) jets[k][j] = Jet(directions[k][j], j);
  }
  Jet basis[ShCoefficientCount(Degree)];
  std::size_t i = 0;
  for (auto _ : state) {
    EvaluateShBasis<Degree>(jets[i++ % kBatch], basis);
    benchmark::DoNotOptimize(basis);
  }
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK_TEMPLATE(BM_ShBasisDouble, 0);
BENCHMARK_TEMPLATE(BM_ShBasisDouble, 1);
BENCHMARK_TEMPLATE(BM_ShBasisDouble, 2);
BENCHMARK_TEMPLATE(BM_ShBasisDouble, 3);
BENCHMARK_TEMPLATE(BM_ShBasisJet, 0);
BENCHMARK_TEMPLATE(BM_ShBasisJet, 1);
BENCHMARK_TEMPLATE(BM_ShBasisJet, 2);
BENCHMARK_TEMPLATE(BM_ShBasisJet, 3);

std::vector<Eigen::Matrix<double, 6, 1>> RandomTangents() {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<Eigen::Matrix<double, 6, 1>> tangents(kBatch);
  for (auto& xi : tangents) {
    for (int j = 0; j < 6; ++j) xi[j] = uniform(rng);
  }
  return tangents;
}

void BM_SE3Exp(benchmark::State& state) {
  const auto tangents = RandomTangents();
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(SE3d::Exp(tangents[i++ % kBatch]));
  state.SetItemsProcessed(state.iterations());
}

void BM_SE3Log(benchmark::State& state) {
  std::vector<SE3d> poses;
  for (const auto& xi : RandomTangents()) poses.push_back(SE3d::Exp(xi));
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(poses[i++ % kBatch].Log());
  state.SetItemsProcessed(state.iterations());
}

void BM_SE3Act(benchmark::State& state) {
  const SE3d pose = SE3d::Exp(RandomTangents().front());
  const auto points = RandomDirections();
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(pose * points[i++ % kBatch]);
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK(BM_SE3Exp);
BENCHMARK(BM_SE3Log);
BENCHMARK(BM_SE3Act);

}  // namespace
}  // namespace radargauss

BENCHMARK_MAIN();
