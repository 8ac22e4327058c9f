// SPDX-License-Identifier: BSD-3-Clause
// The own Gauss-Newton: its normal equations and its step check.

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

// The reported final cost is eq. 2 at the final pose on the final
// association. Associating once (no re-association) on the exact map makes
// that association the one at the initial pose, so it can be rebuilt here.
// The own GN hands the loop the cost it evaluated while checking its last
// step; this checks that it is the cost at the pose it ended on.
TEST(GaussNewton, FinalCostIsEq2AtTheFinalPose) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const MatchingMap& exact = *world.exact;
  const SE3d initial = Perturbed(world.simulated.ground_truth[kTestScan].pose, 0.1, 0.5, 4);
  for (const double w : {0.0, 0.25}) {
    ScanMatchingOptions options;
    options.w_rcs = w;
    options.reassociate = false;
    const ScanMatchingResult result = GaussNewtonSolver(options).Match(scan, exact, initial);
    ASSERT_TRUE(result.converged) << result.reason;
    ASSERT_GT(result.iterations, 1);
    const Correspondences c = FindCorrespondences(scan, exact, 0, initial, options.gate, w > 0.0);
    const double expected = EvaluateCost(c, result.pose, options, {});
    EXPECT_NEAR(result.final_cost, expected, 1e-12 * expected) << "w = " << w;
    EXPECT_EQ(result.n_geo, c.geometric.size());
    EXPECT_EQ(result.n_rcs, c.rcs.size());
  }
}

// The analytic and autodiff linear systems of the own GN are the same.
TEST(GaussNewton, AnalyticAndAutodiffSystemsAgree) {
  const World& world = SimulatedWorld();
  const SE3d pose = Perturbed(world.simulated.ground_truth[kTestScan].pose, 0.1, 0.5, 9);
  const MatchingMap& map = *world.matching;
  for (const RcsTranslation mode : {RcsTranslation::kRotationOnly, RcsTranslation::kFull}) {
    ScanMatchingOptions analytic;
    analytic.w_rcs = 0.25;
    analytic.rcs_translation = mode;
    analytic.geometric_loss = {LossType::kHuber, 1.0};
    ScanMatchingOptions autodiff = analytic;
    autodiff.jacobians = JacobianMode::kAutoDiff;
    const Correspondences c =
        FindCorrespondences(world.simulated.scans[kTestScan], map, map.levels() - 1, pose, 3.0, true);
    ASSERT_GT(c.rcs.size(), 10u);
    const LinearSystem ga = BuildGeometricSystem(c, pose, analytic);
    const LinearSystem gd = BuildGeometricSystem(c, pose, autodiff);
    EXPECT_LT(Relative(ga.H, gd.H), 1e-8);
    EXPECT_LT(Relative(ga.g, gd.g), 1e-8);
    // The analytic path sums terms in pairs (SIMD lanes) and an odd last one
    // alone: both counts agree too.
    Correspondences one_fewer = c;
    one_fewer.geometric.pop_back();
    const LinearSystem fa = BuildGeometricSystem(one_fewer, pose, analytic);
    const LinearSystem fd = BuildGeometricSystem(one_fewer, pose, autodiff);
    EXPECT_LT(Relative(fa.H, fd.H), 1e-8);
    EXPECT_LT(Relative(fa.g, fd.g), 1e-8);
    EXPECT_NEAR(fa.rho_sum, fd.rho_sum, 1e-9 * fa.rho_sum);
    EXPECT_GT(Relative(fa.H, ga.H), 1e-6);
    const LinearSystem ra = BuildRcsSystem(c, pose, analytic);
    const LinearSystem rd = BuildRcsSystem(c, pose, autodiff);
    EXPECT_LT(Relative(ra.H, rd.H), 1e-8);
    EXPECT_LT(Relative(ra.g, rd.g), 1e-8);
    // The summed losses the systems carry give eq. 2 as EvaluateCost does.
    EXPECT_NEAR(ga.rho_sum, gd.rho_sum, 1e-9 * ga.rho_sum);
    EXPECT_NEAR(ra.rho_sum, rd.rho_sum, 1e-9 * ra.rho_sum);
    const double f = 0.75 / double(ga.residuals) * ga.rho_sum + 0.25 / double(ra.residuals) * ra.rho_sum;
    EXPECT_NEAR(f, EvaluateCost(c, pose, analytic, {}), 1e-12 * f);
    if (mode == RcsTranslation::kRotationOnly) {
      // The paper's rotation-only system: the translation rows/columns are
      // the identity, the translation gradient zero, and the rotation block
      // that of the full system (at the association's pose, where the two
      // residuals coincide).
      ScanMatchingOptions full = analytic;
      full.rcs_translation = RcsTranslation::kFull;
      const LinearSystem rf = BuildRcsSystem(c, pose, full);
      const auto block = [](const LinearSystem& system, int row, int col) {
        return Eigen::Matrix3d(system.H.block<3, 3>(row, col));
      };
      EXPECT_EQ(block(ra, kTranslationOffset, kTranslationOffset), Eigen::Matrix3d::Identity());
      EXPECT_TRUE(block(ra, kTranslationOffset, kRotationOffset).isZero(0.0));
      EXPECT_TRUE(block(ra, kRotationOffset, kTranslationOffset).isZero(0.0));
      EXPECT_TRUE(ra.g.segment<3>(kTranslationOffset).isZero(0.0));
      EXPECT_LT(Relative(block(ra, kRotationOffset, kRotationOffset), block(rf, kRotationOffset, kRotationOffset)),
                1e-12);
      EXPECT_LT(Relative(ra.g.segment<3>(kRotationOffset), rf.g.segment<3>(kRotationOffset)), 1e-12);
      EXPECT_GT(block(rf, kTranslationOffset, kTranslationOffset).norm(), 0.0);
    }
    // The losses' curvature: the same from both paths, added beside the IRLS
    // system (which it leaves as it was), zero unless asked.
    EXPECT_TRUE(ga.loss_curvature.isZero(0.0));
    EXPECT_TRUE(ra.loss_curvature.isZero(0.0));
    const LinearSystem gc = BuildGeometricSystem(c, pose, analytic, true);
    const LinearSystem rc = BuildRcsSystem(c, pose, analytic, true);
    EXPECT_GT(gc.loss_curvature.norm(), 1e-3 * gc.H.norm());  // Huber terms beyond a = 1
    EXPECT_GT(rc.loss_curvature.norm(), 1e-3 * rc.H.norm());  // Cauchy
    EXPECT_LT(Relative(gc.loss_curvature, BuildGeometricSystem(c, pose, autodiff, true).loss_curvature), 1e-8);
    EXPECT_LT(Relative(rc.loss_curvature, BuildRcsSystem(c, pose, autodiff, true).loss_curvature), 1e-8);
    EXPECT_EQ(gc.H, ga.H);
    EXPECT_EQ(rc.H, ra.H);
  }
}

// The losses' curvature of one term against the losses written out here:
// with g = rho' J^T r, the term adds c (J^T r)(J^T r)^T = c / rho'^2 g g^T,
// c = max(2 rho'', -rho'/s). Huber (a = 1) beyond a: rho' = s^-1/2,
// rho'' = -s^-3/2 / 2; Cauchy (a = 1): rho' = 1/(1+s), rho'' = -1/(1+s)^2.
TEST(GaussNewton, LossCurvatureOfOneTerm) {
  const World& world = SimulatedWorld();
  const SE3d pose = Perturbed(world.simulated.ground_truth[kTestScan].pose, 0.1, 0.5, 9);
  const MatchingMap& map = *world.matching;
  ScanMatchingOptions options;
  options.geometric_loss = {LossType::kHuber, 1.0};
  options.rcs_loss = {LossType::kCauchy, 1.0};
  const Correspondences all =
      FindCorrespondences(world.simulated.scans[kTestScan], map, map.levels() - 1, pose, 3.0, true);
  int geometric_checked = 0, rcs_checked = 0;
  for (std::size_t k = 0; k < std::min<std::size_t>(all.geometric.size(), 40); ++k) {
    Correspondences one = all;
    one.geometric = {all.geometric[k]};
    const LinearSystem system = BuildGeometricSystem(one, pose, options, true);
    const Eigen::Vector3d r = map.index().SqrtInformationT(all.geometric[k].gaussian) *
                              (pose * all.geometric[k].point_radar - map.index().Mean(all.geometric[k].gaussian));
    const double s = r.squaredNorm();
    const double rho1 = s <= 1.0 ? 1.0 : 1.0 / std::sqrt(s);
    const double rho2 = s <= 1.0 ? 0.0 : -0.5 / (s * std::sqrt(s));
    const double curvature = std::max(2.0 * rho2, -rho1 / s);
    const Eigen::Matrix<double, 6, 6> expected = curvature / (rho1 * rho1) * system.g * system.g.transpose();
    EXPECT_LT((system.loss_curvature - expected).norm(), 1e-9 * std::max(1.0, expected.norm())) << k;
    geometric_checked += s > 1.0;
  }
  for (std::size_t k = 0; k < std::min<std::size_t>(all.rcs.size(), 40); ++k) {
    Correspondences one = all;
    one.rcs = {all.rcs[k]};
    const LinearSystem system = BuildRcsSystem(one, pose, options, true);
    const double r = RcsResidualValue<double>(all.rcs[k], pose.rotation().data(), all.pose.translation());
    const double s = r * r;
    const double rho1 = 1.0 / (1.0 + s), rho2 = -1.0 / ((1.0 + s) * (1.0 + s));
    const double curvature = std::max(2.0 * rho2, -rho1 / s);
    const Eigen::Matrix<double, 6, 6> expected = curvature / (rho1 * rho1) * system.g * system.g.transpose();
    EXPECT_LT((system.loss_curvature - expected).norm(), 1e-9 * std::max(1.0, expected.norm())) << k;
    ++rcs_checked;
  }
  EXPECT_GT(geometric_checked, 3);
  EXPECT_GT(rcs_checked, 10);
}

// The own GN's step check: on one association (no re-association) a step
// never raises eq. 2, whether it is checked at once or by the next
// iteration's system, so the cost after k iterations does not grow with k.
// The planted RCS world 20 deg off, with w = 1: plain GN steps
// (max_step_halvings = 0) overshoot there, and the cost rises above the
// initial one.
TEST(GaussNewton, StepCheckKeepsTheCostFalling) {
  const PlantedRcsWorld world = MakePlantedRcsWorld(IncidenceModel::kOffset, 0.1);
  const MatchingMap single(world.map, ExactMapOnly());
  const SE3d initial(world.truth.rotation() * SO3d::Exp(20.0 * M_PI / 180.0 * Eigen::Vector3d(1, 2, -2).normalized()),
                     world.truth.translation());
  ScanMatchingOptions options;
  options.w_rcs = 1.0;
  options.reassociate = false;
  const double initial_cost =
      EvaluateCost(FindCorrespondences(world.scan, single, 0, initial, options.gate, true), initial, options, {});
  double checked = initial_cost, plain_highest = 0.0;
  for (int k = 1; k <= 12; ++k) {
    options.max_iterations = k;
    const ScanMatchingResult result = GaussNewtonSolver(options, {8, false}).Match(world.scan, single, initial);
    EXPECT_LE(result.final_cost, checked * (1.0 + 1e-12)) << k << " iterations";
    checked = result.final_cost;
    plain_highest =
        std::max(plain_highest, GaussNewtonSolver(options, {0, false}).Match(world.scan, single, initial).final_cost);
  }
  EXPECT_LT(checked, 0.75 * initial_cost);
  EXPECT_GT(plain_highest, initial_cost);
}

}  // namespace
}  // namespace radargauss
