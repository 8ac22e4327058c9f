// SPDX-License-Identifier: BSD-3-Clause
// The Ceres solver and the problem it keeps across associations.

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

// Ceres's iteration limit per association only chunks the solve: on one
// fixed association, 1 or 3 LM iterations per solve end where 100 do, because
// a match ends only once Ceres converged on an association the loop keeps.
TEST(CeresSolver, InnerIterationLimitKeepsTheOptimum) {
  const World& world = SimulatedWorld();
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  for (const double w : {0.0, 0.25}) {
    ScanMatchingOptions options;
    options.w_rcs = w;
    options.reassociate = false;
    options.max_iterations = 200;
    options.translation_tolerance = 1e-12;  // the outer loop stops on Ceres's convergence
    options.rotation_tolerance = 1e-12;
    CeresSolverOptions ceres_options;
    ceres_options.function_tolerance = 1e-12;
    ceres_options.parameter_tolerance = 1e-12;
    const SE3d initial = Perturbed(truth, 0.1, 0.5, 6);
    const RadarScan& scan = world.simulated.scans[kTestScan];
    ceres_options.max_exact_inner_iterations = 100;
    const ScanMatchingResult reference = CeresSolver(options, ceres_options).Match(scan, *world.exact, initial);
    ASSERT_TRUE(reference.converged) << reference.reason;
    EXPECT_EQ(reference.iterations, 1) << "w " << w;  // one solve on the one association
    for (const int limit : {1, 3}) {
      ceres_options.max_exact_inner_iterations = limit;
      const ScanMatchingResult chunked = CeresSolver(options, ceres_options).Match(scan, *world.exact, initial);
      ASSERT_TRUE(chunked.converged) << chunked.reason;
      double dt = 0.0, dr = 0.0;
      PoseErrors(chunked.pose, reference.pose, dt, dr);
      EXPECT_LT(dt, 1e-6) << "w " << w << ", limit " << limit;
      EXPECT_LT(dr, 1e-5) << "w " << w << ", limit " << limit;
      if (limit == 1) {
        EXPECT_GT(chunked.iterations, 1) << "w " << w;  // the limit did cut the solve
      }
    }
  }
}

// A solve of the last stage also ends once an accepted step is below the
// step tolerances, as the own GN stops: with tolerances no step reaches,
// one association (no re-association) ends after one LM step, where
// max_exact_inner_iterations = 1 takes it too; tight tolerances go on.
TEST(CeresSolver, ExactMapSolveEndsOnASmallStep) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const SE3d initial = Perturbed(world.simulated.ground_truth[kTestScan].pose, 0.1, 0.5, 8);
  for (const double w : {0.0, 0.25}) {
    ScanMatchingOptions loose;
    loose.w_rcs = w;
    loose.geometric_loss = {LossType::kCauchy, 1.0};  // not solved in one step
    loose.reassociate = false;
    loose.translation_tolerance = 1e3;
    loose.rotation_tolerance = 1e3;
    ScanMatchingOptions one_step = loose;
    one_step.max_iterations = 1;
    CeresSolverOptions one_iteration;
    one_iteration.max_exact_inner_iterations = 1;
    ScanMatchingOptions tight = loose;
    tight.translation_tolerance = tight.rotation_tolerance = 1e-12;
    const ScanMatchingResult a = CeresSolver(loose).Match(scan, *world.exact, initial);
    const ScanMatchingResult b = CeresSolver(one_step, one_iteration).Match(scan, *world.exact, initial);
    const ScanMatchingResult c = CeresSolver(tight).Match(scan, *world.exact, initial);
    ASSERT_TRUE(a.converged) << a.reason;
    EXPECT_EQ(a.iterations, 1);
    double dt = 0.0, dr = 0.0;
    PoseErrors(a.pose, b.pose, dt, dr);
    EXPECT_LT(dt, 1e-12) << "w " << w;
    EXPECT_LT(dr, 1e-10) << "w " << w;
    PoseErrors(a.pose, c.pose, dt, dr);
    EXPECT_GT(dt + dr, 1e-6) << "w " << w;  // the tight solve went on
  }
}

// On the exact map a solve ends once the pose leaves the association's
// re-association thresholds: with thresholds of zero (re-associate after every
// step) a cap of 50 iterations per solve does what a cap of one does.
TEST(CeresSolver, ExactMapSolveEndsWhenThePoseLeavesTheAssociation) {
  const World& world = SimulatedWorld();
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  for (const double w : {0.0, 0.25}) {
    ScanMatchingOptions options;
    options.w_rcs = w;
    options.reassociation_translation = 0.0;
    options.reassociation_rotation = 0.0;
    const SE3d initial = Perturbed(truth, 0.1, 0.5, 7);
    const RadarScan& scan = world.simulated.scans[kTestScan];
    CeresSolverOptions one, fifty;
    one.max_exact_inner_iterations = 1;
    fifty.max_exact_inner_iterations = 50;
    const ScanMatchingResult a = CeresSolver(options, one).Match(scan, *world.exact, initial);
    const ScanMatchingResult b = CeresSolver(options, fifty).Match(scan, *world.exact, initial);
    ASSERT_TRUE(a.converged) << a.reason;
    ASSERT_GT(a.iterations, 2) << "w " << w;  // several associations
    EXPECT_EQ(a.iterations, b.iterations) << "w " << w;
    double dt = 0.0, dr = 0.0;
    PoseErrors(a.pose, b.pose, dt, dr);
    EXPECT_LT(dt, 1e-12) << "w " << w;
    EXPECT_LT(dr, 1e-10) << "w " << w;
  }
  CeresSolverOptions none;
  none.max_exact_inner_iterations = 0;
  EXPECT_THROW(CeresSolver(ScanMatchingOptions(), none), std::invalid_argument);
}

// The ways CeresScanProblem can hold the terms.
struct Layout {
  JacobianMode jacobians;
  CeresBlocks blocks;  // asked for; autodiff terms always take a block each
  int threads;
  const char* name;
};
const Layout kLayoutList[] = {
    {JacobianMode::kAutoDiff, CeresBlocks::kSquareRoot, 1, "autodiff"},
    {JacobianMode::kAnalytic, CeresBlocks::kShared, 1, "analytic, shared rows"},
    {JacobianMode::kAnalytic, CeresBlocks::kPerTerm, 1, "analytic, a block per term"},
    {JacobianMode::kAnalytic, CeresBlocks::kSquareRoot, 1, "analytic, square root"},
    {JacobianMode::kAnalytic, CeresBlocks::kSquareRoot, 3, "analytic, square root, 3 threads"}};

// The residual blocks of n terms in a layout.
std::size_t BlocksOf(const Layout& layout, std::size_t n) {
  if (layout.jacobians == JacobianMode::kAutoDiff || layout.blocks == CeresBlocks::kPerTerm) return n;
  if (layout.blocks == CeresBlocks::kShared) {
    return (n + CeresScanProblem::kTermsPerBlock - 1) / CeresScanProblem::kTermsPerBlock;
  }
  return std::min<std::size_t>(n, std::size_t(layout.threads));
}

// The residuals of n terms with `rows` rows each on a tangent space of `tangent`.
std::size_t ResidualsOf(const Layout& layout, std::size_t n, int rows, int tangent) {
  const bool square_root = layout.jacobians == JacobianMode::kAnalytic && layout.blocks == CeresBlocks::kSquareRoot;
  return square_root ? BlocksOf(layout, n) * (tangent + 1) : n * rows;
}

ScanMatchingOptions LayoutOptions(const Layout& layout, RcsTranslation mode, bool trivial) {
  ScanMatchingOptions options;
  options.jacobians = layout.jacobians;
  options.rcs_translation = mode;
  options.geometric_loss = trivial ? LossConfig{LossType::kTrivial, 1.0} : LossConfig{LossType::kHuber, 0.5};
  if (trivial) options.rcs_loss = {LossType::kTrivial, 1.0};
  return options;
}

// Two layouts' gradients over the same updates, entry by entry.
void ExpectSameGradient(const std::vector<double>& gradient, const std::vector<double>& reference,
                        const std::string& label) {
  ASSERT_EQ(gradient.size(), reference.size());
  for (std::size_t i = 0; i < reference.size(); ++i) {
    EXPECT_NEAR(gradient[i], reference[i], 1e-8 * (1.0 + std::abs(reference[i]))) << "entry " << i << ", " << label;
  }
}

// The problem's residual blocks and residuals for correspondences c at weight w.
void ExpectBlockCounts(CeresScanProblem& problem, const Layout& layout, const Correspondences& c, double w,
                       RcsTranslation mode) {
  const std::size_t n_geo = w < 1.0 ? c.geometric.size() : 0;
  const std::size_t n_rcs = w > 0.0 ? c.rcs.size() : 0;
  const int rcs_tangent = mode == RcsTranslation::kRotationOnly ? 3 : 6;
  EXPECT_EQ(problem.problem().NumResidualBlocks(), int(BlocksOf(layout, n_geo) + BlocksOf(layout, n_rcs)))
      << "w " << w << ", " << layout.name;
  EXPECT_EQ(problem.problem().NumResiduals(),
            int(ResidualsOf(layout, n_geo, 3, 6) + ResidualsOf(layout, n_rcs, 1, rcs_tangent)))
      << "w " << w << ", " << layout.name;
}

// The problem's Jacobian `dense` (at the blocks' values) against central
// differences of its residuals along the tangent coordinates x = [dphi; dt]
// (Ceres's Jacobian columns: rotation, then translation), entry by entry.
void ExpectCentralDifferenceJacobian(CeresScanProblem& problem, Eigen::Vector4d& rotation, Eigen::Vector3d& translation,
                                     const Eigen::MatrixXd& dense, const std::string& label) {
  const Eigen::Vector4d rotation0 = rotation;
  const Eigen::Vector3d translation0 = translation;
  const Eigen::MatrixXd numeric = NumericJacobian(
      [&](const Eigen::VectorXd& x) {
        SO3Manifold().Plus(rotation0.data(), x.data(), rotation.data());
        translation = translation0 + x.tail<3>();
        std::vector<double> values;
        EXPECT_TRUE(problem.problem().Evaluate(ceres::Problem::EvaluateOptions(), nullptr, &values, nullptr, nullptr));
        return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(values.data(), Eigen::Index(values.size())));
      },
      Eigen::VectorXd::Zero(6));
  rotation = rotation0;
  translation = translation0;
  ASSERT_EQ(dense.rows(), numeric.rows());
  double worst = 0.0;
  for (int row = 0; row < dense.rows(); ++row) {
    const Eigen::Matrix<double, 1, 6> difference = dense.row(row) - numeric.row(row);
    const Eigen::Matrix<double, 1, 6> scale = dense.row(row).cwiseAbs() + numeric.row(row).cwiseAbs();
    worst = std::max(worst, (difference.cwiseAbs().array() / (1e-6 + scale.array())).maxCoeff());
  }
  EXPECT_LT(worst, 1e-5) << label;
}

// The Ceres problem kept across associations holds exactly the latest
// association: after updates that grow and shrink the term counts, change
// level and weight, its cost (Ceres: 1/2 sum) is eq. 2 as EvaluateCost gives
// it, in one block per term, shared blocks of kTermsPerBlock terms, or one
// square-root block per thread; for both RCS translation modes, robust and
// trivial losses. Its gradient is the same whether the terms are blocks of
// their own under Ceres's loss handling (autodiff, and analytic per term) or
// share blocks with their loss in the residual (analytic): the shared blocks
// place each term's rows and apply its loss consistently. The shared blocks'
// Jacobian is their residuals' derivative (central differences on the
// manifold), and the square-root blocks' Jacobian J has the shared rows'
// Gauss-Newton matrix J^T J.
TEST(CeresScanProblem, HoldsExactlyTheLatestAssociation) {
  const World& world = SimulatedWorld();
  const MatchingMap& map = *world.matching;
  const RadarScan& full_scan = world.simulated.scans[kTestScan];
  RadarScan half_scan = full_scan;
  half_scan.points.resize(full_scan.points.size() / 2);
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  const auto& layouts = kLayoutList;
  constexpr int kLayouts = int(std::size(kLayoutList));
  struct Update {
    const RadarScan* scan;
    std::size_t level;
    double w;
  };
  const Update updates[] = {{&full_scan, map.levels() - 1, 0.25}, {&half_scan, 0, 0.0},
                            {&full_scan, map.levels() - 1, 0.0},  {&half_scan, map.levels() - 1, 0.5},
                            {&full_scan, map.levels() - 1, 1.0},  {&full_scan, map.levels() - 1, 0.25}};
  for (const bool trivial : {false, true}) {
    for (const RcsTranslation mode : {RcsTranslation::kRotationOnly, RcsTranslation::kFull}) {
      std::vector<double> gradients[kLayouts];                 // per layout, all updates in a row
      std::vector<Eigen::Matrix<double, 6, 6>> shared_normal;  // J^T J of the shared rows, per update
      for (int l = 0; l < kLayouts; ++l) {
        const Layout& layout = layouts[l];
        const ScanMatchingOptions options = LayoutOptions(layout, mode, trivial);
        const bool analytic = layout.jacobians == JacobianMode::kAnalytic;
        const bool shared_rows = analytic && layout.blocks == CeresBlocks::kShared;
        const bool square_root = analytic && layout.blocks == CeresBlocks::kSquareRoot;
        const SE3d pose = Perturbed(truth, 0.1, 0.5, 3);
        Eigen::Vector4d rotation = pose.rotation().quaternion().coeffs();
        Eigen::Vector3d translation = pose.translation();
        CeresScanProblem problem(options, {}, rotation.data(), translation.data(), layout.blocks, layout.threads);
        int u = 0;
        for (const Update& update : updates) {
          const Correspondences c = FindCorrespondences(*update.scan, map, update.level, pose, 3.0, update.w > 0.0);
          ASSERT_GT(c.geometric.size(), 2 * CeresScanProblem::kTermsPerBlock);
          if (update.w > 0.0) {
            ASSERT_GT(c.rcs.size(), CeresScanProblem::kTermsPerBlock);
          }
          problem.Update(c, update.w);
          ScanMatchingOptions weighted = options;
          weighted.w_rcs = update.w;
          ExpectBlockCounts(problem, layout, c, update.w, mode);
          double cost = 0.0;
          std::vector<double> gradient;
          ceres::CRSMatrix jacobian;
          ASSERT_TRUE(problem.problem().Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, &gradient,
                                                 analytic ? &jacobian : nullptr));
          const double f = EvaluateCost(c, pose, weighted, {});
          EXPECT_NEAR(2.0 * cost, f, 1e-12 * f) << "w " << update.w << " level " << update.level << ", " << layout.name;
          // With residuals only (a candidate step's cost), the same cost.
          double cost_only = 0.0;
          ASSERT_TRUE(
              problem.problem().Evaluate(ceres::Problem::EvaluateOptions(), &cost_only, nullptr, nullptr, nullptr));
          EXPECT_NEAR(cost_only, cost, 1e-14 * cost) << layout.name;
          gradients[l].insert(gradients[l].end(), gradient.begin(), gradient.end());
          if (!analytic) continue;
          ASSERT_EQ(jacobian.num_cols, 6);
          const Eigen::MatrixXd dense = Dense(jacobian);
          const Eigen::Matrix<double, 6, 6> normal = dense.transpose() * dense;
          if (shared_rows) shared_normal.push_back(normal);
          if (square_root) {
            ASSERT_LT(std::size_t(u), shared_normal.size());
            const double scale = shared_normal[u].cwiseAbs().maxCoeff();
            EXPECT_LT((normal - shared_normal[u]).cwiseAbs().maxCoeff(), 1e-10 * scale)
                << "w " << update.w << ", " << layout.name;
          }
          ++u;
          if (shared_rows) {
            ExpectCentralDifferenceJacobian(problem, rotation, translation, dense,
                                            "w " + std::to_string(update.w) + (trivial ? ", trivial" : ", robust"));
          }
        }
      }
      for (int l = 1; l < kLayouts; ++l) {
        ExpectSameGradient(gradients[l], gradients[0],
                           std::string(layouts[l].name) + (trivial ? ", trivial" : ", robust"));
      }
    }
  }
}

// A square-root block whose terms do not span the tangent space (one
// geometric term: rank 3 of 6; two rotation-only RCS terms: rank 2 of 3)
// takes its square root from J^T J's eigenvectors: cost, gradient and J^T J
// are still those of the shared rows, and nothing is NaN.
TEST(CeresScanProblem, SquareRootOfARankDeficientBlock) {
  const World& world = SimulatedWorld();
  const SE3d pose = Perturbed(world.simulated.ground_truth[kTestScan].pose, 0.1, 0.5, 3);
  Correspondences c = FindCorrespondences(world.simulated.scans[kTestScan], *world.exact, 0, pose, 3.0, true);
  ASSERT_GE(c.rcs.size(), 2u);
  c.geometric.resize(1);
  c.rcs.resize(2);
  struct Evaluation {
    double cost = 0.0;
    std::vector<double> gradient;
    Eigen::Matrix<double, 6, 6> normal;
  };
  const auto evaluate = [&](CeresBlocks blocks) {
    Eigen::Vector4d rotation = pose.rotation().quaternion().coeffs();
    Eigen::Vector3d translation = pose.translation();
    CeresScanProblem problem(ScanMatchingOptions(), {}, rotation.data(), translation.data(), blocks);
    problem.Update(c, 0.5);
    Evaluation e;
    ceres::CRSMatrix jacobian;
    EXPECT_TRUE(
        problem.problem().Evaluate(ceres::Problem::EvaluateOptions(), &e.cost, nullptr, &e.gradient, &jacobian));
    const Eigen::MatrixXd dense = Dense(jacobian);
    EXPECT_TRUE(dense.allFinite());
    e.normal = dense.transpose() * dense;
    return e;
  };
  const Evaluation rows = evaluate(CeresBlocks::kShared);
  const Evaluation root = evaluate(CeresBlocks::kSquareRoot);
  EXPECT_NEAR(root.cost, rows.cost, 1e-12 * rows.cost);
  ASSERT_EQ(root.gradient.size(), rows.gradient.size());
  for (std::size_t i = 0; i < rows.gradient.size(); ++i) {
    EXPECT_NEAR(root.gradient[i], rows.gradient[i], 1e-9 * (1.0 + std::abs(rows.gradient[i]))) << "entry " << i;
  }
  EXPECT_LT((root.normal - rows.normal).cwiseAbs().maxCoeff(), 1e-10 * rows.normal.cwiseAbs().maxCoeff());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(rows.normal);
  EXPECT_LT(eigen.eigenvalues()[0], 1e-9 * eigen.eigenvalues()[5]);  // the case this test is for
}

}  // namespace
}  // namespace radargauss
