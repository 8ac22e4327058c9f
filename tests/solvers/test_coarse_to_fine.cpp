// SPDX-License-Identifier: BSD-3-Clause
// The outer loop: lazy re-association, the RCS terms of an association, the
// geometric stage on the exact map.

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
#include "radargauss/map/builder.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/core/sh.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "radargauss/residuals/geometric_residual.hpp"
#include "radargauss/residuals/loss.hpp"
#include "radargauss/residuals/rcs_residual.hpp"
#include "radargauss/solvers/ceres_solver.hpp"
#include "radargauss/solvers/factory.hpp"
#include "radargauss/solvers/gauss_newton.hpp"
#include "radargauss/solvers/multi_hypothesis.hpp"
#include "radargauss/solvers/joint_refinement.hpp"
#include "support/scan_matching_fixtures.hpp"

namespace radargauss {
namespace {

using testing::NumericJacobian;
using testing::RandomUnitVector;

// Lazy re-association on the exact map: the solver keeps the association
// while the pose stays within the thresholds of where it was made. With the
// thresholds at 0 it re-associates after every step (the textbook loop);
// both end at the same optimum to well within the association's own
// resolution, the lazy one with fewer associations (fewer iterations here,
// as small steps do not make points swap Gaussians back and forth).
TEST(LazyReassociation, SameOptimumFewerIterations) {
  const World& world = SimulatedWorld();
  const MatchingMap& exact = *world.exact;
  double eager_iterations = 0.0, lazy_iterations = 0.0;
  for (const int scan : {20, 40, 60}) {
    const SE3d truth = world.simulated.ground_truth[scan].pose;
    const SE3d initial = Perturbed(truth, 0.05, 0.2, std::uint32_t(scan));
    ScanMatchingOptions eager;
    eager.reassociation_translation = eager.reassociation_rotation = 0.0;
    const ScanMatchingOptions lazy;
    const ScanMatchingResult a = GaussNewtonSolver(eager).Match(world.simulated.scans[scan], exact, initial);
    const ScanMatchingResult b = GaussNewtonSolver(lazy).Match(world.simulated.scans[scan], exact, initial);
    double dt = 0.0, dr = 0.0;
    PoseErrors(a.pose, b.pose, dt, dr);
    EXPECT_LT(dt, 0.02) << "scan " << scan;
    EXPECT_LT(dr, 0.1) << "scan " << scan;
    EXPECT_TRUE(b.converged) << b.reason;
    eager_iterations += a.iterations;
    lazy_iterations += b.iterations;
  }
  std::printf("iterations over 3 scans: eager %.0f, lazy %.0f\n", eager_iterations, lazy_iterations);
  EXPECT_LT(lazy_iterations, eager_iterations);
}

// AddRcsTerms gives the RCS terms FindCorrespondences makes with_rcs, from
// the geometric pairs alone; each pair names the scan point it came from.
TEST(Correspondences, AddRcsTermsAsAssociatingWithRcs) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const MatchingMap& exact = *world.exact;
  const SE3d pose = Perturbed(world.simulated.ground_truth[kTestScan].pose, 0.1, 0.5, 3);
  const Correspondences with_rcs = FindCorrespondences(scan, exact, 0, pose, 3.0, true);
  Correspondences added = FindCorrespondences(scan, exact, 0, pose, 3.0, false);
  EXPECT_TRUE(added.rcs.empty());
  for (const GeometricTerm& pair : added.geometric) {
    ASSERT_LT(pair.point, scan.points.size());
    EXPECT_EQ(scan.points[pair.point].position, pair.point_radar);
  }
  AddRcsTerms(scan, exact, added);
  ASSERT_GT(with_rcs.rcs.size(), 100u);
  ASSERT_EQ(added.rcs.size(), with_rcs.rcs.size());
  for (std::size_t k = 0; k < added.rcs.size(); ++k) {
    const RcsTerm &a = added.rcs[k], &b = with_rcs.rcs[k];
    EXPECT_EQ(a.gaussian, b.gaussian) << k;
    EXPECT_EQ(a.point_radar, b.point_radar) << k;
    EXPECT_EQ(a.measurement, b.measurement) << k;
    EXPECT_EQ(a.facing, b.facing) << k;
    EXPECT_EQ(a.coefficients, b.coefficients) << k;
  }
  ScanMatchingOptions options;
  options.w_rcs = 0.25;
  EXPECT_EQ(EvaluateCost(added, pose, options, {}), EvaluateCost(with_rcs, pose, options, {}));
  AddRcsTerms(scan, exact, added);  // replaces, does not append
  EXPECT_EQ(added.rcs.size(), with_rcs.rcs.size());
  RadarScan no_rcs = scan;
  no_rcs.has_rcs = false;
  AddRcsTerms(no_rcs, exact, added);
  EXPECT_TRUE(added.rcs.empty());
}

// geometric_first: with 0 < w < 1 the exact map is matched with the
// geometric term alone (coarse tolerances), then with eq. 2 on that stage's
// last association while the pose stays within its re-association
// thresholds (a new association otherwise). Without it, without
// re-association, and with w = 0 or 1: eq. 2 alone on the exact map.
TEST(GeometricFirst, ExactMapGeometricStageThenEq2) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const MatchingMap& matching = *world.matching;
  const std::size_t coarse = matching.levels() - 1;
  const SE3d initial = Perturbed(world.simulated.ground_truth[kTestScan].pose, 0.1, 0.5, 5);
  struct Seen {
    bool finest;
    double w, translation_tolerance;
    Correspondences c;
  };
  // One iteration per stage; `move` shifts the pose by that much (x) in the
  // exact map's geometric stage.
  const auto stages = [&](const ScanMatchingOptions& options, double move) {
    std::vector<Seen> seen;
    const ScanPriors none;
    CoarseToFine match(scan, matching, initial, options, none);
    for (const Stage& stage : match.stages()) {
      if (!match.Associate(stage, 1)) break;
      seen.push_back({stage.finest, stage.options.w_rcs, stage.translation_tolerance, match.correspondences()});
      if (stage.finest && stage.options.w_rcs == 0.0 && move > 0.0) {
        match.pose() = SE3d(match.pose().rotation(), match.pose().translation() + Eigen::Vector3d(move, 0, 0));
      }
    }
    return seen;
  };
  ScanMatchingOptions options;
  options.w_rcs = 0.25;
  std::vector<Seen> seen = stages(options, 0.0);
  ASSERT_EQ(seen.size(), coarse + 2);
  for (std::size_t k = 0; k < coarse; ++k) EXPECT_FALSE(seen[k].finest);
  const Seen &geometric = seen[coarse], &full = seen[coarse + 1];
  EXPECT_TRUE(geometric.finest && full.finest);
  EXPECT_EQ(geometric.w, 0.0);
  EXPECT_TRUE(geometric.c.rcs.empty());
  EXPECT_EQ(geometric.translation_tolerance, options.coarse_translation_tolerance);
  EXPECT_EQ(full.w, 0.25);
  EXPECT_EQ(full.translation_tolerance, options.translation_tolerance);
  // The same association, now with its RCS terms.
  EXPECT_TRUE(SamePose(full.c.pose, geometric.c.pose));
  ASSERT_EQ(full.c.geometric.size(), geometric.c.geometric.size());
  for (std::size_t k = 0; k < full.c.geometric.size(); ++k) {
    EXPECT_EQ(full.c.geometric[k].gaussian, geometric.c.geometric[k].gaussian) << k;
  }
  EXPECT_EQ(full.c.rcs.size(), FindCorrespondences(scan, matching, coarse, full.c.pose, options.gate, true).rcs.size());
  EXPECT_GT(full.c.rcs.size(), 0u);
  // A geometric stage that moves the pose within the thresholds: its association is kept.
  seen = stages(options, 0.5 * options.reassociation_translation);
  ASSERT_EQ(seen.size(), coarse + 2);
  EXPECT_TRUE(SamePose(seen[coarse + 1].c.pose, seen[coarse].c.pose));
  // A geometric stage that moves the pose past the thresholds: eq. 2 associates anew there.
  seen = stages(options, 2.0 * options.reassociation_translation);
  ASSERT_EQ(seen.size(), coarse + 2);
  const double moved = (seen[coarse + 1].c.pose.translation() - seen[coarse].c.pose.translation()).x();
  EXPECT_NEAR(moved, 2.0 * options.reassociation_translation, 1e-12);
  EXPECT_GT(seen[coarse + 1].c.rcs.size(), 0u);
  // Eq. 2 alone on the exact map.
  ScanMatchingOptions off = options;
  off.geometric_first = false;
  ScanMatchingOptions once = options;
  once.reassociate = false;
  ScanMatchingOptions zero = options;
  zero.w_rcs = 0.0;
  for (const ScanMatchingOptions& o : {off, once, zero}) {
    seen = stages(o, 0.0);
    ASSERT_EQ(seen.size(), coarse + 1);
    EXPECT_EQ(seen.back().w, o.w_rcs);
    EXPECT_EQ(seen.back().translation_tolerance, o.translation_tolerance);
  }
  ScanMatchingOptions one = options;
  one.w_rcs = 1.0;
  seen = stages(one, 0.0);
  ASSERT_EQ(seen.size(), 1u);  // no coarse levels, no geometric stage
  EXPECT_EQ(seen[0].w, 1.0);
}

// The same optimum with and without geometric_first (to the association's
// resolution), within 5 cm / 0.2 deg of the truth, from the paper's initial
// errors (coarse levels) and from a tracking error (exact map alone), for
// the own GN and Ceres LM at w = 0.25.
TEST(GeometricFirst, SameOptimumAsEq2Throughout) {
  const World& world = SimulatedWorld();
  for (const int scan : {kTestScan, 60}) {
    const SE3d truth = world.simulated.ground_truth[scan].pose;
    for (const bool far : {true, false}) {
      const SE3d initial = far ? Perturbed(truth, 2.0, 5.0, std::uint32_t(scan)) : Perturbed(truth, 0.05, 0.2, 7);
      const MatchingMap& map = far ? *world.matching : *world.exact;
      for (const std::string solver : {"gn", "ceres"}) {
        ScanMatchingOptions first;
        first.w_rcs = 0.25;
        ScanMatchingOptions throughout = first;
        throughout.geometric_first = false;
        const ScanMatchingResult a = MakeScanMatcher(solver, first)->Match(world.simulated.scans[scan], map, initial);
        const ScanMatchingResult b =
            MakeScanMatcher(solver, throughout)->Match(world.simulated.scans[scan], map, initial);
        const std::string where = solver + ", scan " + std::to_string(scan) + (far ? ", 2 m / 5 deg" : ", tracking");
        ASSERT_TRUE(a.converged) << a.reason << " " << where;
        ASSERT_TRUE(b.converged) << b.reason << " " << where;
        double dt = 0.0, dr = 0.0;
        PoseErrors(a.pose, b.pose, dt, dr);
        std::printf("%s: %.4f m / %.4f deg apart, iterations %d / %d\n", where.c_str(), dt, dr, a.iterations,
                    b.iterations);
        EXPECT_LT(dt, 0.02) << where;  // the association's resolution, as LazyReassociation
        EXPECT_LT(dr, 0.1) << where;
        PoseErrors(a.pose, truth, dt, dr);
        EXPECT_LT(dt, 0.05) << where;
        EXPECT_LT(dr, 0.2) << where;
        EXPECT_GT(a.n_rcs, 0u) << where;
      }
    }
  }
}

// The match's covariance on a planted case: 60 Gaussians of random shape
// around the radar; each of 200 scans draws 8 points per Gaussian from it
// with isotropic noise of known std added, and, in the second case, an
// offset common to a Gaussian's points (its mean one estimate, off by it).
// The mean predicted std of each pose axis is within 20 % of the spread of
// the matched poses' errors over the draws; the Gauss-Newton matrix's
// inverse (N_geo information)^-1 misses it by more in both cases.
TEST(MatchCovariance, PredictsTheSpreadOfThePoseOverNoiseDraws) {
  const SE3d truth(SO3d::Exp(Eigen::Vector3d(0.02, -0.01, 0.3)), Eigen::Vector3d(2.0, 1.0, 0.2));
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  GaussianMap map;
  for (int g = 0; g < 60; ++g) {
    const double azimuth = (uniform(rng) - 0.5) * 2.0, elevation = (uniform(rng) - 0.5) * 0.4;
    const double range = 5.0 + 25.0 * uniform(rng);
    const Eigen::Vector3d radar = range * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                                          std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    Gaussian gaussian;
    gaussian.mean = truth * radar;
    const Eigen::Matrix3d axes = SO3d::Exp(Eigen::Vector3d(normal(rng), normal(rng), normal(rng))).Matrix();
    const Eigen::Vector3d stds(0.05 + 0.4 * uniform(rng), 0.05 + 0.4 * uniform(rng), 0.03 + 0.1 * uniform(rng));
    gaussian.covariance = axes * stds.cwiseAbs2().asDiagonal() * axes.transpose();
    gaussian.point_count = 8;
    map.gaussians.push_back(gaussian);
  }
  const MatchingMap matching(map, ExactMapOnly());
  ScanMatchingOptions options;
  options.gate = 6.0;
  options.translation_tolerance = 1e-7;
  options.rotation_tolerance = 1e-8;
  options.pose_covariance = true;
  const GaussNewtonSolver solver(options);
  constexpr double kPointNoise = 0.08;  // m
  for (const double shared : {0.0, 0.06}) {
    constexpr int kDraws = 200;
    Eigen::Matrix<double, 6, 6> predicted = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 6> from_information = Eigen::Matrix<double, 6, 6>::Zero();
    std::vector<Eigen::Matrix<double, 6, 1>> errors;
    for (int draw = 0; draw < kDraws; ++draw) {
      RadarScan scan;
      for (const Gaussian& gaussian : map.gaussians) {
        const Eigen::LLT<Eigen::Matrix3d> factor(gaussian.covariance);
        const Eigen::Vector3d offset = shared * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
        for (int k = 0; k < 8; ++k) {
          const Eigen::Vector3d spread(normal(rng), normal(rng), normal(rng));
          const Eigen::Vector3d noise = kPointNoise * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
          RadarPoint point;
          point.position = truth.Inverse() * (gaussian.mean + factor.matrixL() * spread + noise + offset);
          scan.points.push_back(point);
        }
      }
      const ScanMatchingResult result = solver.Match(scan, matching, truth);
      ASSERT_TRUE(result.converged) << result.reason;
      predicted += result.covariance / kDraws;
      from_information += (double(result.n_geo) * result.information).inverse() / kDraws;
      Eigen::Matrix<double, 6, 1> error;
      error.segment<3>(kTranslationOffset) = result.pose.translation() - truth.translation();
      error.segment<3>(kRotationOffset) = (truth.rotation().Inverse() * result.pose.rotation()).Log();
      errors.push_back(error);
    }
    Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero();
    for (const auto& error : errors) mean += error / kDraws;
    Eigen::Matrix<double, 6, 1> spread = Eigen::Matrix<double, 6, 1>::Zero();
    for (const auto& error : errors) spread += (error - mean).cwiseAbs2() / (kDraws - 1);
    spread = spread.cwiseSqrt();
    const Eigen::Matrix<double, 6, 1> stated = predicted.diagonal().cwiseSqrt();
    const Eigen::Matrix<double, 6, 1> naive = from_information.diagonal().cwiseSqrt();
    const Eigen::Matrix<double, 6, 1> ratio = stated.cwiseQuotient(spread);
    const Eigen::Matrix<double, 6, 1> naive_ratio = naive.cwiseQuotient(spread);
    EXPECT_LT((ratio.array() - 1.0).abs().maxCoeff(), 0.2) << "shared " << shared << ": " << ratio.transpose();
    EXPECT_GT((naive_ratio.array() - 1.0).abs().minCoeff(), 0.2)
        << "shared " << shared << ": " << naive_ratio.transpose();
  }
}

}  // namespace
}  // namespace radargauss
