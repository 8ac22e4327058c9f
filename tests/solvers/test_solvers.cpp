// SPDX-License-Identifier: BSD-3-Clause
// Every solver on the same cases: convergence, agreement, rotation-only RCS,
// degenerate inputs, option validation.

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

class SolverTest : public ::testing::TestWithParam<SolverCase> {};

// From 2 m / 5 deg initial error, to within 5 cm / 0.2 deg of the reference.
TEST_P(SolverTest, ConvergesFromTwoMetresFiveDegrees) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  ScanMatchingOptions options;
  options.w_rcs = GetParam().w_rcs;
  const auto solver = MakeSolver(GetParam().name, options);
  for (const std::uint32_t seed : {1u, 2u, 3u}) {
    const ScanMatchingResult result = solver->Match(scan, *world.matching, Perturbed(truth, 2.0, 5.0, seed));
    double dt = 0.0, dr = 0.0;
    PoseErrors(result.pose, truth, dt, dr);
    EXPECT_TRUE(result.converged) << result.reason;
    EXPECT_LT(dt, 0.05) << GetParam().name << " seed " << seed;
    EXPECT_LT(dr, 0.2) << GetParam().name << " seed " << seed;
    EXPECT_GT(result.n_geo, scan.points.size() / 2);
    if (options.w_rcs > 0.0) {
      EXPECT_GT(result.n_rcs, 10u);
    }
    EXPECT_TRUE(std::isfinite(result.final_cost));
  }
}

INSTANTIATE_TEST_SUITE_P(EverySolver, SolverTest,
                         ::testing::Values(SolverCase{"gn", 0.0}, SolverCase{"gn", 0.25},
                                           SolverCase{"gn-autodiff", 0.0}, SolverCase{"gn-autodiff", 0.25},
                                           SolverCase{"ceres", 0.0}, SolverCase{"ceres", 0.25},
                                           SolverCase{"mh-gn", 0.0}, SolverCase{"mh-gn", 0.25}),
                         [](const ::testing::TestParamInfo<SolverCase>& info) {
                           std::string name = info.param.name + "_w" + std::to_string(int(info.param.w_rcs * 100));
                           for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

// An RCS term holds the facing sign of its association's pose: there its
// residual is the paper's, and as the point crosses its Gaussian's y-z plane
// it stays continuous, where the paper's flip of d jumps by the odd SH bands.
TEST(RcsFacing, HeldFromTheAssociationPose) {
  RcsTerm term;
  term.mean = Eigen::Vector3d(10.0, 0.0, 0.0);
  term.point_radar = Eigen::Vector3d(10.0 + 1e-3, 1.0, 0.2);  // u = (1e-3, 1, 0.2) at the identity
  term.measurement = 0.1;
  term.degree = 1;
  term.coefficients[1] = 0.8;  // Y_1, odd in d.y
  term.incidence = IncidenceModel::kOffset;
  const SE3d associated_at;
  term.facing = FacingSign(IncidenceVector(term.incidence, term.point_radar, Eigen::Vector3d(term.mean)));
  EXPECT_EQ(term.facing, -1.0);
  const auto held = [&](const SE3d& pose) {
    return RcsResidualValue<double>(term, pose.rotation().data(), pose.translation());
  };
  EXPECT_NEAR(held(associated_at), PaperRcsResidual(term, associated_at), 1e-15);
  const SE3d crossed(SO3d(), Eigen::Vector3d(-2e-3, 0.0, 0.0));  // u.x = -1e-3
  EXPECT_LT(std::abs(held(crossed) - held(associated_at)), 1e-2);
  EXPECT_GT(std::abs(PaperRcsResidual(term, crossed) - PaperRcsResidual(term, associated_at)), 0.5);

  // Every term of a simulated scan's association is the paper's at that pose.
  const World& world = SimulatedWorld();
  const SE3d pose = Perturbed(world.simulated.ground_truth[kTestScan].pose, 0.1, 1.0, 3);
  const Correspondences c = FindCorrespondences(world.simulated.scans[kTestScan], *world.matching,
                                                world.matching->levels() - 1, pose, 3.0, true);
  ASSERT_GT(c.rcs.size(), 50u);
  int flipped = 0;
  for (const RcsTerm& t : c.rcs) {
    EXPECT_NEAR(RcsResidualValue<double>(t, pose.rotation().data(), pose.translation()), PaperRcsResidual(t, pose),
                1e-12);
    flipped += t.facing < 0.0;
  }
  EXPECT_GT(flipped, 0);  // both signs occur
  EXPECT_LT(flipped, int(c.rcs.size()));
}

// Own GN and Ceres LM reach the same optimum on the same association, for
// both incidence models (the association holds each RCS term's facing sign,
// so the cost they minimise is smooth); so do Ceres with each layout of its
// blocks and Ceres's dogleg, and the own GN with the losses' curvature.
TEST(SolverAgreement, SameOptimumOnSameAssociation) {
  const World& world = SimulatedWorld();
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  for (const auto& [w, map] : std::vector<std::pair<double, const GaussianMap*>>{
           {0.0, &world.map}, {0.25, &world.view_map}, {0.25, &world.map}}) {
    const MatchingMap single(*map, ExactMapOnly());  // no coarse levels: one association
    ScanMatchingOptions options;
    options.w_rcs = w;
    options.reassociate = false;
    options.max_iterations = 200;
    options.translation_tolerance = 1e-9;
    options.rotation_tolerance = 1e-10;
    CeresSolverOptions ceres_options;
    ceres_options.max_exact_inner_iterations = 200;
    ceres_options.function_tolerance = 1e-12;
    ceres_options.gradient_tolerance = 1e-12;
    ceres_options.parameter_tolerance = 1e-10;
    const SE3d initial = Perturbed(truth, 0.05, 0.3, 4);
    const ScanMatchingResult gn = GaussNewtonSolver(options).Match(world.simulated.scans[kTestScan], single, initial);
    const ScanMatchingResult lm =
        CeresSolver(options, ceres_options).Match(world.simulated.scans[kTestScan], single, initial);
    // A residual block per term under Ceres's own loss handling, and shared
    // rows without the square-root form: other paths, the same optimum.
    CeresSolverOptions unshared = ceres_options;
    unshared.blocks = CeresBlocks::kPerTerm;
    const ScanMatchingResult lm_unshared =
        CeresSolver(options, unshared).Match(world.simulated.scans[kTestScan], single, initial);
    CeresSolverOptions rows = ceres_options;
    rows.blocks = CeresBlocks::kShared;
    const ScanMatchingResult lm_rows =
        CeresSolver(options, rows).Match(world.simulated.scans[kTestScan], single, initial);
    // Dogleg on the square-root blocks (its Cauchy point reads the gradient and J^T J as LM does).
    CeresSolverOptions dogleg = ceres_options;
    dogleg.dogleg = true;
    const ScanMatchingResult dl = CeresSolver(options, dogleg).Match(world.simulated.scans[kTestScan], single, initial);
    // The losses' curvature in the own GN's Hessian changes its path, not its optimum.
    const ScanMatchingResult gn_curved =
        GaussNewtonSolver(options, {8, true}).Match(world.simulated.scans[kTestScan], single, initial);
    const std::pair<const ScanMatchingResult*, const char*> variants[] = {
        {&lm_unshared, "a block per term"}, {&lm_rows, "shared rows"}, {&dl, "dogleg"}, {&gn_curved, "loss curvature"}};
    for (const auto& [variant, name] : variants) {
      ASSERT_TRUE(variant->converged) << variant->reason;
      ExpectPoseNear(variant->pose, lm.pose, 1e-4, 1e-4, "w " + std::to_string(w) + ", " + name);
    }
    double dt = 0.0, dr = 0.0;
    PoseErrors(gn.pose, lm.pose, dt, dr);
    std::printf("w %.2f, %s incidence: GN cost %.10f (%d it), LM cost %.10f; pose difference %.2e m, %.2e rad\n", w,
                ToString(map->incidence).c_str(), gn.final_cost, gn.iterations, lm.final_cost, dt, dr * M_PI / 180.0);
    ASSERT_TRUE(gn.converged) << gn.reason;
    EXPECT_LT(dt, 1e-4) << "w " << w;
    EXPECT_LT(dr * M_PI / 180.0, 1e-4) << "w " << w;
    EXPECT_NEAR(gn.final_cost, lm.final_cost, 1e-6 + 1e-4 * gn.final_cost);
  }
}

// w = 1 with rotation-only RCS: the translation does not move. On the
// simulated world's fitted models the RCS term alone does not reduce a pure
// rotation error (1 deg ends at 1.2 to 2.8 deg with either incidence model:
// the fits' RMSE, 0.35 to 0.45 normalised, swamps the signal); that is
// measured and printed here, and the planted-model test below shows the
// reduction where the models are right.
TEST(RotationOnlyRcs, TranslationFixedAtWeightOne) {
  const World& world = SimulatedWorld();
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  ScanMatchingOptions options;
  options.w_rcs = 1.0;
  options.reassociate = false;  // the association of the initial pose
  for (const GaussianMap* map : {&world.view_map, &world.map}) {
    const MatchingMap single(*map, ExactMapOnly());
    for (const std::string name : {"gn", "ceres"}) {
      const auto solver = MakeSolver(name, options);
      const SE3d shifted(truth.rotation(), truth.translation() + Eigen::Vector3d(0.3, -0.2, 0.1));
      const ScanMatchingResult moved = solver->Match(world.simulated.scans[kTestScan], single, shifted);
      EXPECT_EQ(moved.pose.translation(), shifted.translation()) << name;
      // Pure rotation error of 1 degree about z.
      const SE3d rotated(truth.rotation() * SO3d::Exp(Eigen::Vector3d(0, 0, M_PI / 180.0)), truth.translation());
      const ScanMatchingResult result = solver->Match(world.simulated.scans[kTestScan], single, rotated);
      double dt = 0.0, dr = 0.0;
      PoseErrors(result.pose, truth, dt, dr);
      EXPECT_EQ(dt, 0.0) << name;
      std::printf("%s, w = 1, %s incidence, RCS alone: rotation error 1.000 -> %.3f deg\n", name.c_str(),
                  ToString(map->incidence).c_str(), dr);
      EXPECT_TRUE(std::isfinite(dr));
      EXPECT_LT(dr, 10.0) << name;  // bounded, even where it does not help
    }
  }
}

TEST(RotationOnlyRcs, RcsAloneReducesAPureRotationErrorOnPlantedModels) {
  // Exact patterns: both incidence models recover the truth (to 1e-5 deg:
  // the last steps differ between GCC and clang builds by ~1e-6 deg, far
  // below the stopping rule's 1e-4 rad). With RCS noise
  // of 0.1 (normalised units, a twentieth of the range) the paper's offset
  // incidence still does, to < 0.1 deg: mu_r moves by range x angle against
  // the fixed p_r, so d turns much faster than the pose. The view incidence
  // turns d only by the pose's own angle; its signal over 1 deg is ~100x
  // below that noise, and it ends at 1.2 deg there (measured, not asserted).
  // Eager re-association, so that the final association is made at the
  // final pose: with the lazy default, the facing signs are those of a pose
  // up to 0.1 deg away, and Ceres ends 0.01 deg off without noise (measured).
  for (const auto& [incidence, rcs_noise] : std::vector<std::pair<IncidenceModel, double>>{
           {IncidenceModel::kView, 0.0}, {IncidenceModel::kOffset, 0.0}, {IncidenceModel::kOffset, 0.1}}) {
    const PlantedRcsWorld world = MakePlantedRcsWorld(incidence, rcs_noise);
    const MatchingMap single(world.map, ExactMapOnly());
    ScanMatchingOptions options;
    options.w_rcs = 1.0;
    options.max_iterations = 50;
    options.reassociation_translation = 0.0;
    options.reassociation_rotation = 0.0;
    for (const std::string name : {"gn", "gn-autodiff", "ceres"}) {
      const auto solver = MakeSolver(name, options);
      for (const Eigen::Vector3d& axis : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 2, -2).normalized()}) {
        const SE3d rotated(world.truth.rotation() * SO3d::Exp(M_PI / 180.0 * axis), world.truth.translation());
        const ScanMatchingResult result = solver->Match(world.scan, single, rotated);
        double dt = 0.0, dr = 0.0;
        PoseErrors(result.pose, world.truth, dt, dr);
        std::printf("%s, %s incidence, planted RCS, noise %.1f, w = 1: rotation error 1.000 -> %.4f deg (N_rcs %zu)\n",
                    name.c_str(), ToString(incidence).c_str(), rcs_noise, dr, result.n_rcs);
        EXPECT_EQ(dt, 0.0) << name;
        EXPECT_GT(result.n_rcs, world.scan.points.size() / 2) << name;
        EXPECT_LT(dr, rcs_noise == 0.0 ? 1e-5 : 0.1) << name << ", " << ToString(incidence) << " incidence";
      }
    }
  }
}

// Degenerate inputs: converged = false with a reason, never NaN, never a crash.
TEST(DegenerateInputs, FailWithAReason) {
  const World& world = SimulatedWorld();
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  RadarScan empty;
  empty.has_rcs = empty.has_doppler = true;
  RadarScan one = empty;
  one.points.push_back(world.simulated.scans[kTestScan].points.front());
  RadarScan far_away = world.simulated.scans[kTestScan];
  for (RadarPoint& p : far_away.points) p.position += Eigen::Vector3d(0, 0, 500.0);
  RadarScan outliers = world.simulated.scans[kTestScan];
  for (RadarPoint& p : outliers.points) p.rcs = 1000.0;
  for (const std::string name : {"gn", "gn-autodiff", "ceres", "ceres-dogleg", "mh-gn"}) {
    for (const auto& [scan, w] : std::vector<std::pair<const RadarScan*, double>>{
             {&empty, 0.0}, {&one, 0.0}, {&far_away, 0.0}, {&outliers, 0.25}, {&outliers, 1.0}}) {
      ScanMatchingOptions options;
      options.w_rcs = w;
      const ScanMatchingResult result = MakeSolver(name, options)->Match(*scan, *world.matching, truth);
      EXPECT_FALSE(result.converged) << name << " " << scan->points.size() << " points, w " << w;
      EXPECT_FALSE(result.reason.empty()) << name;
      EXPECT_TRUE(result.pose.Matrix().allFinite()) << name;
      EXPECT_TRUE(std::isfinite(result.final_cost)) << name;
    }
  }
}

TEST(ScanMatchingOptionsTest, Validation) {
  ScanMatchingOptions options;
  options.w_rcs = 1.5;
  EXPECT_THROW(GaussNewtonSolver{options}, std::invalid_argument);
  options.w_rcs = 0.5;
  options.gate = 0.0;
  EXPECT_THROW(CeresSolver{options}, std::invalid_argument);
  MultiHypothesisOptions hypotheses;
  hypotheses.starts = 14;
  EXPECT_THROW(HypothesisOffsets(hypotheses), std::invalid_argument);
  EXPECT_THROW(MakeScanMatcher("lm", ScanMatchingOptions{}), std::invalid_argument);
  ScanMatchingOptions lazy;
  lazy.reassociation_translation = -0.01;
  EXPECT_THROW(GaussNewtonSolver{lazy}, std::invalid_argument);
}

}  // namespace
}  // namespace radargauss
