// SPDX-License-Identifier: BSD-3-Clause
// The residuals, analytic twin against autodiff (one evaluation with
// Jacobians), and the parts of one outer iteration on the exact map:
// association and the normal equations.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <type_traits>

#include "bench_world.hpp"
#include "radargauss/residuals/geometric_residual.hpp"
#include "radargauss/residuals/imu_residual.hpp"
#include "radargauss/residuals/radar_inertial_residuals.hpp"
#include "radargauss/residuals/rcs_residual.hpp"
#include "radargauss/solvers/normal_equations.hpp"

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

// The preintegrated IMU term between two states (0.1 s at 200 Hz), 15 x 32 Jacobians.
template <typename Kind>
void BM_ImuResidual(benchmark::State& state) {
  ImuPreintegration between(ImuBias{}, ImuNoise{});
  for (int k = 0; k < 20; ++k) {
    between.Integrate(Eigen::Vector3d(0.01, -0.02, 0.3), Eigen::Vector3d(0.5, 0.1, 9.81), 0.005);
  }
  const auto cost = MakeCost<Kind, ImuCostFunction, ImuResidual>(between, ImuNoise{});
  Eigen::Vector4d qi = SO3d::Exp(Eigen::Vector3d(0.1, -0.2, 0.3)).quaternion().coeffs();
  Eigen::Vector4d qj = SO3d::Exp(Eigen::Vector3d(0.1, -0.2, 0.33)).quaternion().coeffs();
  Eigen::Vector3d pi(1.0, 2.0, 0.5), pj(1.6, 2.0, 0.5);
  Eigen::Matrix<double, 9, 1> mi = Eigen::Matrix<double, 9, 1>::Zero(), mj = mi;
  mi(0) = mj(0) = 6.0;
  const double* parameters[6] = {qi.data(), pi.data(), mi.data(), qj.data(), pj.data(), mj.data()};
  double residuals[15], j0[60], j1[45], j2[135], j3[60], j4[45], j5[135];
  double* jacobians[6] = {j0, j1, j2, j3, j4, j5};
  for (auto _ : state) {
    cost->Evaluate(parameters, residuals, jacobians);
    benchmark::DoNotOptimize(j2[0]);
  }
}
BENCHMARK_TEMPLATE(BM_ImuResidual, Analytic);
BENCHMARK_TEMPLATE(BM_ImuResidual, AutoDiff);

// The radar's pose term on an IMU state (7 blocks, 26 parameters).
template <typename Kind>
void BM_RadarPoseResidual(benchmark::State& state) {
  const SE3d measured(SO3d::Exp(Eigen::Vector3d(0.0, 0.02, 0.4)), Eigen::Vector3d(10.0, 2.0, 0.8));
  const ImuAtScan imu{Eigen::Vector3d(0, 0, 0.3), Eigen::Vector3d(0, 0, 9.8), 0.0};
  const Eigen::Matrix<double, 6, 6> W = Eigen::Matrix<double, 6, 6>::Identity() * 10.0;
  const auto cost = MakeCost<Kind, RadarPoseCostFunction, RadarPoseResidual>(measured, W, imu);
  Eigen::Vector4d q = SO3d::Exp(Eigen::Vector3d(0.0, 0.02, 0.41)).quaternion().coeffs(), qe(0, 0, 0, 1);
  Eigen::Vector3d p(10.1, 2.0, 0.8), te(0.5, 0.1, -0.2);
  Eigen::Matrix<double, 9, 1> m = Eigen::Matrix<double, 9, 1>::Zero();
  Eigen::Vector2d tilt(0.01, -0.02);
  double clock = 0.01;
  const double* parameters[7] = {q.data(), p.data(), m.data(), qe.data(), te.data(), tilt.data(), &clock};
  double residuals[6], j0[24], j1[18], j2[54], j3[24], j4[18], j5[12], j6[6];
  double* jacobians[7] = {j0, j1, j2, j3, j4, j5, j6};
  for (auto _ : state) {
    cost->Evaluate(parameters, residuals, jacobians);
    benchmark::DoNotOptimize(j0[0]);
  }
}
BENCHMARK_TEMPLATE(BM_RadarPoseResidual, Analytic);
BENCHMARK_TEMPLATE(BM_RadarPoseResidual, AutoDiff);

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

// Args: incidence model, Gamma shape k of the likelihood (0: decibel).
template <typename Kind>
void BM_RcsResidualRotationOnly(benchmark::State& state) {
  RcsTerm term = BenchmarkTerm(IncidenceModel(state.range(0)));
  term.shape = double(state.range(1));
  if (term.shape > 0.0) {  // a Gaussian of scale 4 dB and offset 1 dB (rcs_likelihood.hpp)
    term.log_scale = 0.2302585 * 4.0;
    term.log_offset = -0.2302585;
  }
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
  state.SetLabel(ToString(term.incidence) + ", degree 3" + (term.shape > 0.0 ? ", swerling1" : ""));
}
BENCHMARK_TEMPLATE(BM_RcsResidualRotationOnly, Analytic)->Args({0, 0})->Args({1, 0})->Args({0, 1});
BENCHMARK_TEMPLATE(BM_RcsResidualRotationOnly, AutoDiff)->Args({0, 0})->Args({1, 0})->Args({0, 1});

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

}  // namespace
}  // namespace radargauss

BENCHMARK_MAIN();
