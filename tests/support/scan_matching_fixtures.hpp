// SPDX-License-Identifier: BSD-3-Clause
// Shared fixtures of the scan-matching tests: Ceres evaluation helpers, the
// simulated world and its map, planted and hand-built maps, and the paper's
// incidence law written out as an independent reference.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/crs_matrix.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <iterator>
#include <memory>
#include <cctype>
#include <cmath>
#include <limits>
#include <random>

#include "radargauss/experiment/experiment.hpp"
#include "radargauss/lie/manifold.hpp"
#include "radargauss/map/pipeline.hpp"
#include "radargauss/core/sh.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "radargauss/residuals/geometric_residual.hpp"
#include "radargauss/residuals/rcs_residual.hpp"
#include "radargauss/residuals/robust_loss.hpp"
#include "radargauss/residuals/rotation_residual.hpp"
#include "radargauss/residuals/velocity_residual.hpp"
#include "radargauss/solvers/ceres_scan_problem.hpp"
#include "radargauss/solvers/ceres_solver.hpp"
#include "radargauss/solvers/coarse_to_fine.hpp"
#include "radargauss/solvers/factory.hpp"
#include "radargauss/solvers/gauss_newton.hpp"
#include "radargauss/solvers/joint_refinement.hpp"
#include "radargauss/solvers/multi_hypothesis.hpp"
#include "radargauss/solvers/normal_equations.hpp"
#include "cost_function_checks.hpp"
#include "test_util.hpp"

namespace radargauss {

using testing::NumericJacobian;
using testing::RandomUnitVector;

inline RcsTerm RandomRcsTerm(std::mt19937& rng, IncidenceModel incidence) {
  std::normal_distribution<double> normal;
  RcsTerm term;
  term.point_radar = Eigen::Vector3d(8.0 + normal(rng), 2.0 * normal(rng), normal(rng));
  term.mean = Eigen::Vector3d(3.0 * normal(rng), 3.0 * normal(rng), normal(rng)) + Eigen::Vector3d(10, 0, 0);
  term.measurement = 0.3;
  term.degree = 3;
  for (double& c : term.coefficients) c = 0.5 * normal(rng);
  term.incidence = incidence;
  return term;
}

struct World {
  SimulatedSequence simulated;
  GaussianMap map;       // RCS models with the paper's offset incidence
  GaussianMap view_map;  // the same Gaussians, RCS models with view incidence
  std::unique_ptr<MatchingMap> matching;
  std::unique_ptr<MatchingMap> exact;  // the map alone (ExactMapOnly): one association at a time
};

// One association (no re-association) solved to tight tolerances, eq. 2 at
// w = 0.25: the options under which two solvers must reach the same optimum.
inline ScanMatchingOptions OneAssociationToConvergence() {
  ScanMatchingOptions options;
  options.w_rcs = 0.25;
  options.reassociate = false;
  options.translation_tolerance = 1e-7;
  options.rotation_tolerance = 1e-8;
  options.max_iterations = 100;
  return options;
}

// Ceres to its optimum, not to its default tolerances.
inline CeresSolverOptions CeresToItsOptimum() {
  CeresSolverOptions tight;
  tight.max_exact_inner_iterations = 200;
  tight.function_tolerance = 1e-12;
  tight.gradient_tolerance = 1e-12;
  tight.parameter_tolerance = 1e-10;
  return tight;
}

inline const World& SimulatedWorld() {
  static const World* world = [] {
    auto* w = new World;
    SimulationConfig config;
    config.scans = 80;
    config.seed = 5;
    w->simulated = Simulate(config);
    const Sequence sequence = AsSequence(w->simulated);
    const MapGeometry geometry = BuildMapGeometry(sequence.scans, sequence.poses);
    w->map = FitRcs(geometry);
    RcsFitOptions view;
    view.incidence = IncidenceModel::kView;
    w->view_map = FitRcs(geometry, view);
    w->matching = std::make_unique<MatchingMap>(w->map);
    w->exact = std::make_unique<MatchingMap>(w->map, ExactMapOnly());
    return w;
  }();
  return *world;
}

// Expects `estimate` within `translation` m and `rotation` rad of `reference`.
inline void ExpectPoseNear(const SE3d& estimate, const SE3d& reference, double translation, double rotation,
                           const std::string& label) {
  double dt = 0.0, dr_deg = 0.0;
  PoseErrors(estimate, reference, dt, dr_deg);
  EXPECT_LT(dt, translation) << label;
  EXPECT_LT(dr_deg * M_PI / 180.0, rotation) << label;
}

constexpr int kTestScan = 40;

inline SE3d Perturbed(const SE3d& pose, double translation, double angle_deg, std::uint32_t seed) {
  std::mt19937 rng(seed);
  return SE3d(pose.rotation() * SO3d::Exp(angle_deg * M_PI / 180.0 * RandomUnitVector(rng)),
              pose.translation() + translation * RandomUnitVector(rng));
}

struct SolverCase {
  std::string name;
  double w_rcs;
};

inline std::unique_ptr<ScanMatcher> MakeSolver(const std::string& name, const ScanMatchingOptions& options) {
  return MakeScanMatcher(name, options);
}

// The paper's incidence direction, written out (the reference the library's
// IncidenceVector and FacingSign are tested against): d = normalize(u),
// u = p_r - mu_r (offset) or -mu_r (view), flipped when d.x > 0.
inline Eigen::Vector3d PaperIncidenceDirection(IncidenceModel incidence, const Eigen::Vector3d& point_radar,
                                               const Eigen::Vector3d& mean_radar) {
  Eigen::Vector3d d =
      incidence == IncidenceModel::kOffset ? Eigen::Vector3d(point_radar - mean_radar) : Eigen::Vector3d(-mean_radar);
  d.normalize();
  if (d.x() > 0.0) d = -d;
  return d;
}

// The paper's RCS residual, with the direction re-evaluated at `pose`.
inline double PaperRcsResidual(const RcsTerm& term, const SE3d& pose) {
  const Eigen::Vector3d mean_radar = pose.rotation().Inverse() * (term.mean - pose.translation());
  const Eigen::Vector3d d = PaperIncidenceDirection(term.incidence, term.point_radar, mean_radar);
  return term.measurement - EvaluateSh<double>(term.degree, term.coefficients.data(), d);
}

// A Jacobian Ceres returned (compressed rows) as a dense matrix.
inline Eigen::MatrixXd Dense(const ceres::CRSMatrix& jacobian) {
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(jacobian.num_rows, jacobian.num_cols);
  for (int row = 0; row < jacobian.num_rows; ++row) {
    for (int k = jacobian.rows[row]; k < jacobian.rows[row + 1]; ++k) dense(row, jacobian.cols[k]) = jacobian.values[k];
  }
  return dense;
}

// A pure rotation error reduced by the RCS term alone, on planted
// parameters: Gaussians 6 to 12 m around the radar whose RCS models are
// planted degree-2 SH patterns, and a scan whose RCS values are those
// patterns evaluated at the true pose with the incidence law of docs/design/map.md,
// "Building the map", written out here independently of the residual code. With
// w = 1 and rotation-only the geometric term has no weight, so whatever
// corrects the rotation is the RCS term.
struct PlantedRcsWorld {
  GaussianMap map;
  RadarScan scan;
  SE3d truth;
};

inline PlantedRcsWorld MakePlantedRcsWorld(IncidenceModel incidence, double rcs_noise) {
  PlantedRcsWorld world;
  world.map.incidence = incidence;
  world.truth = SE3d(SO3d::Exp(Eigen::Vector3d(0.05, -0.03, 0.4)), Eigen::Vector3d(3.0, -1.0, 0.5));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coefficient(-0.35, 0.35), offset(-0.12, 0.12);
  std::normal_distribution<double> noise(0.0, rcs_noise);
  world.scan.has_rcs = true;
  for (int azimuth = -60; azimuth <= 60; azimuth += 10) {
    for (const int elevation : {-8, 0, 8}) {
      const double range = 6.0 + 3.0 * ((azimuth / 10 + elevation / 8 + 9) % 3);
      const double a = azimuth * M_PI / 180.0, e = elevation * M_PI / 180.0;
      const Eigen::Vector3d mean_radar =
          range * Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
      Gaussian g;
      g.mean = world.truth * mean_radar;
      g.covariance = 0.15 * 0.15 * Eigen::Matrix3d::Identity();
      g.rcs.degree = 2;
      g.rcs.median = 0.0;
      g.rcs.scale = 1.0;
      for (int i = 1; i < ShCoefficientCount(2); ++i) g.rcs.coefficients[i] = coefficient(rng);
      for (int k = 0; k < 12; ++k) {
        RadarPoint point;
        point.position = world.truth.Inverse() * (g.mean + Eigen::Vector3d(offset(rng), offset(rng), offset(rng)));
        // d in the radar frame at the true pose.
        const Eigen::Vector3d d = PaperIncidenceDirection(incidence, point.position, mean_radar);
        const Eigen::Matrix<double, 9, 1> basis = ShBasis<2, double>(d);
        point.rcs = basis.dot(Eigen::Map<const Eigen::Matrix<double, 9, 1>>(g.rcs.coefficients.data())) + noise(rng);
        world.scan.points.push_back(point);
      }
      world.map.gaussians.push_back(g);
    }
  }
  return world;
}

// The hand-built map of the coarse-level tests: one Gaussian at the origin,
// Sigma = 0.01 I (0.1 m std).
inline GaussianMap OneGaussianAtTheOrigin() {
  GaussianMap map;
  Gaussian g;
  g.covariance = 0.01 * Eigen::Matrix3d::Identity();
  g.point_count = 10;
  map.gaussians = {g};
  return map;
}

// A scan of points at `positions` (no RCS, no Doppler).
inline RadarScan ScanOf(const std::vector<Eigen::Vector3d>& positions) {
  RadarScan scan;
  for (const Eigen::Vector3d& p : positions) {
    RadarPoint point;
    point.position = p;
    scan.points.push_back(point);
  }
  return scan;
}

}  // namespace radargauss
