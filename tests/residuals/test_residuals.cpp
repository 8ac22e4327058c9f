// SPDX-License-Identifier: BSD-3-Clause
// The cost functors: analytic twins against autodiff and central differences.

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

#include "radargauss/experiment.hpp"
#include "radargauss/lie/manifold.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/sh.hpp"
#include "radargauss/simulator.hpp"
#include "radargauss/residuals/geometric_residual.hpp"
#include "radargauss/residuals/loss.hpp"
#include "radargauss/residuals/rcs_residual.hpp"
#include "radargauss/solvers/ceres_solver.hpp"
#include "radargauss/solvers/factory.hpp"
#include "radargauss/solvers/gauss_newton.hpp"
#include "radargauss/solvers/multi_hypothesis.hpp"
#include "radargauss/solvers/joint_refinement.hpp"
#include "radargauss/residuals/rotation_residual.hpp"
#include "radargauss/residuals/velocity_residual.hpp"
#include "support/scan_matching_fixtures.hpp"

namespace radargauss {
namespace {

using testing::NumericJacobian;
using testing::RandomUnitVector;

// ---------------------------------------------------------------------------
// Jacobians: analytic twin vs autodiff vs central differences, in the ambient
// parameters (quaternion x y z w, translation).

class JacobianTest : public ::testing::TestWithParam<IncidenceModel> {};

TEST(ResidualJacobians, GeometricAnalyticAutodiffNumeric) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Vector4d q = SO3d::Exp(2.0 * RandomUnitVector(rng)).quaternion().coeffs();
    Eigen::Vector3d t = 5.0 * RandomUnitVector(rng);
    const Eigen::Vector3d p = 10.0 * RandomUnitVector(rng);
    const Eigen::Vector3d mean = 3.0 * RandomUnitVector(rng);
    Eigen::Matrix3d A = Eigen::Matrix3d::Random();
    const Eigen::Matrix3d LT = (A * A.transpose() + Eigen::Matrix3d::Identity()).llt().matrixU();
    const GeometricCostFunction analytic(p, mean, LT);
    const std::unique_ptr<ceres::CostFunction> autodiff(GeometricResidual::Create(p, mean, LT));
    std::vector<Eigen::MatrixXd> ja, jd;
    const std::vector<double*> blocks = {q.data(), t.data()};
    const Eigen::VectorXd ra = EvaluateWithJacobians(analytic, blocks, ja);
    const Eigen::VectorXd rd = EvaluateWithJacobians(*autodiff, blocks, jd);
    EXPECT_LT((ra - rd).norm(), 1e-12);
    for (int b = 0; b < 2; ++b) {
      EXPECT_LT(Relative(ja[b], jd[b]), 1e-8) << "block " << b;
      EXPECT_LT(Relative(ja[b], NumericBlockJacobian(analytic, blocks, b)), 1e-5) << "block " << b;
    }
  }
}

TEST_P(JacobianTest, RcsAnalyticAutodiffNumeric) {
  std::mt19937 rng(2);
  for (int trial = 0; trial < 20; ++trial) {
    RcsTerm term = RandomRcsTerm(rng, GetParam());
    Eigen::Vector4d q = SO3d::Exp(0.5 * RandomUnitVector(rng)).quaternion().coeffs();
    Eigen::Vector3d t = RandomUnitVector(rng);
    const Eigen::Vector3d mean_radar = Eigen::Map<const Eigen::Quaterniond>(q.data()).conjugate() * (term.mean - t);
    term.facing = FacingSign(IncidenceVector(term.incidence, term.point_radar, mean_radar));  // as associated here
    // Full: rotation and translation blocks.
    const RcsCostFunction analytic(term);
    const std::unique_ptr<ceres::CostFunction> autodiff(RcsResidual::Create(term));
    std::vector<Eigen::MatrixXd> ja, jd;
    const std::vector<double*> blocks = {q.data(), t.data()};
    const Eigen::VectorXd ra = EvaluateWithJacobians(analytic, blocks, ja);
    const Eigen::VectorXd rd = EvaluateWithJacobians(*autodiff, blocks, jd);
    EXPECT_NEAR(ra[0], rd[0], 1e-12);
    double cost_only = 0.0;  // the residual-only path (no Jacobians requested)
    ASSERT_TRUE(analytic.Evaluate(blocks.data(), &cost_only, nullptr));
    EXPECT_NEAR(cost_only, ra[0], 1e-14);
    for (int b = 0; b < 2; ++b) {
      EXPECT_LT(Relative(ja[b], jd[b]), 1e-8) << "block " << b;
      EXPECT_LT(Relative(ja[b], NumericBlockJacobian(analytic, blocks, b)), 1e-5) << "block " << b;
    }
    // Rotation only.
    const RcsRotationCostFunction analytic_rotation(term, t);
    const std::unique_ptr<ceres::CostFunction> autodiff_rotation(RcsRotationResidual::Create(term, t));
    const std::vector<double*> rotation_block = {q.data()};
    const Eigen::VectorXd rotation_residual = EvaluateWithJacobians(analytic_rotation, rotation_block, ja);
    EvaluateWithJacobians(*autodiff_rotation, rotation_block, jd);
    ASSERT_TRUE(analytic_rotation.Evaluate(rotation_block.data(), &cost_only, nullptr));
    EXPECT_NEAR(cost_only, rotation_residual[0], 1e-14);
    EXPECT_LT(Relative(ja[0], jd[0]), 1e-8);
    EXPECT_LT(Relative(ja[0], NumericBlockJacobian(analytic_rotation, rotation_block, 0)), 1e-5);
  }
}

// Joint refinement's RCS residual with the coefficients as a parameter block:
// analytic vs autodiff vs numeric, rotation-only and full, every SH degree.
TEST_P(JacobianTest, RcsCoefficientBlocksAnalyticAutodiffNumeric) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 20; ++trial) {
    RcsTerm term = RandomRcsTerm(rng, GetParam());
    term.degree = trial % (kMaxShDegree + 1);
    Eigen::Vector4d q = SO3d::Exp(0.5 * RandomUnitVector(rng)).quaternion().coeffs();
    Eigen::Vector3d t = RandomUnitVector(rng);
    const Eigen::Vector3d mean_radar = Eigen::Map<const Eigen::Quaterniond>(q.data()).conjugate() * (term.mean - t);
    term.facing = FacingSign(IncidenceVector(term.incidence, term.point_radar, mean_radar));
    Eigen::VectorXd c(ShCoefficientCount(term.degree));
    for (int i = 0; i < c.size(); ++i) c[i] = 0.5 * normal(rng);  // not the term's own
    for (const bool full : {false, true}) {
      const RcsCoefficientCostFunction analytic(term, t, full);
      const std::unique_ptr<ceres::CostFunction> autodiff(RcsCoefficientResidual::Create(term, t, full));
      ASSERT_EQ(analytic.parameter_block_sizes(), autodiff->parameter_block_sizes());
      std::vector<double*> blocks = {q.data(), c.data()};
      if (full) blocks.push_back(t.data());
      std::vector<Eigen::MatrixXd> ja, jd;
      const Eigen::VectorXd ra = EvaluateWithJacobians(analytic, blocks, ja);
      const Eigen::VectorXd rd = EvaluateWithJacobians(*autodiff, blocks, jd);
      EXPECT_NEAR(ra[0], rd[0], 1e-12);
      // The coefficients of the block, not the term's, predict the RCS.
      double d_norm = 0.0;
      const Eigen::Vector3d d = RcsDirection<double>(term, mean_radar, d_norm);
      EXPECT_NEAR(ra[0], term.measurement - EvaluateSh(term.degree, c.data(), d), 1e-12);
      double cost_only = 0.0;
      ASSERT_TRUE(analytic.Evaluate(blocks.data(), &cost_only, nullptr));
      EXPECT_NEAR(cost_only, ra[0], 1e-14);
      for (std::size_t b = 0; b < blocks.size(); ++b) {
        EXPECT_LT(Relative(ja[b], jd[b]), 1e-8) << "block " << b << " degree " << term.degree;
        EXPECT_LT(Relative(ja[b], NumericBlockJacobian(analytic, blocks, int(b))), 1e-5) << "block " << b;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(BothIncidenceModels, JacobianTest,
                         ::testing::Values(IncidenceModel::kOffset, IncidenceModel::kView));

// The Doppler velocity term: analytic twin against autodiff and central
// differences; zero where the translation is the previous pose plus
// R_prev v dt; W^T W is the inverse of S dt^2 + Q.
TEST(ResidualJacobians, VelocityTermAnalyticAutodiffNumeric) {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 20; ++trial) {
    const SE3d previous(SO3d::Exp(RandomUnitVector(rng)), 10.0 * RandomUnitVector(rng));
    const Eigen::Vector3d velocity = 8.0 * RandomUnitVector(rng);
    const double dt = 0.1;
    Eigen::Matrix3d A = Eigen::Matrix3d::Random();
    const Eigen::Matrix3d S = 0.01 * A * A.transpose();
    const Eigen::Matrix3d W = VelocitySqrtInformation(S, dt, 1e-4 * Eigen::Matrix3d::Identity());
    EXPECT_LT(((W.transpose() * W).inverse() - (S * dt * dt + 1e-4 * Eigen::Matrix3d::Identity())).norm(), 1e-12);
    const VelocityCostFunction analytic(previous, velocity, dt, W);
    const std::unique_ptr<ceres::CostFunction> autodiff(VelocityResidual::Create(previous, velocity, dt, W));
    Eigen::Vector3d t = previous.translation() + previous.rotation() * (velocity * dt);
    std::vector<Eigen::MatrixXd> J_analytic, J_autodiff;
    EXPECT_LT(EvaluateWithJacobians(analytic, {t.data()}, J_analytic).norm(), 1e-9);
    t += 0.3 * RandomUnitVector(rng);
    const Eigen::VectorXd r_analytic = EvaluateWithJacobians(analytic, {t.data()}, J_analytic);
    const Eigen::VectorXd r_autodiff = EvaluateWithJacobians(*autodiff, {t.data()}, J_autodiff);
    EXPECT_LT(Relative(r_analytic, r_autodiff), 1e-12);
    EXPECT_LT(Relative(J_analytic[0], J_autodiff[0]), 1e-8);
    EXPECT_LT(Relative(J_analytic[0], NumericBlockJacobian(analytic, {t.data()}, 0)), 1e-5);
  }
}

// The rotation term: analytic twin against autodiff and central differences
// in the ambient quaternion, zero at the prediction, and its tangent
// Jacobian W Jr^-1 against central differences along R Exp(dphi).
TEST(ResidualJacobians, RotationTermAnalyticAutodiffNumeric) {
  std::mt19937 rng(23);
  for (int trial = 0; trial < 20; ++trial) {
    RotationPrior prior;
    prior.predicted = SO3d::Exp(2.0 * RandomUnitVector(rng));
    prior.sqrt_information = Eigen::Vector3d(300.0, 200.0, 5.0).asDiagonal();
    const RotationCostFunction analytic(prior);
    const std::unique_ptr<ceres::CostFunction> autodiff(
        RotationResidual::Create(prior.predicted, prior.sqrt_information));
    Eigen::Vector4d q = prior.predicted.quaternion().coeffs();
    std::vector<Eigen::MatrixXd> J_analytic, J_autodiff;
    EXPECT_LT(EvaluateWithJacobians(analytic, {q.data()}, J_analytic).norm(), 1e-9);
    const SO3d rotation = prior.predicted * SO3d::Exp(0.4 * RandomUnitVector(rng));
    q = rotation.quaternion().coeffs();
    const Eigen::VectorXd r_analytic = EvaluateWithJacobians(analytic, {q.data()}, J_analytic);
    const Eigen::VectorXd r_autodiff = EvaluateWithJacobians(*autodiff, {q.data()}, J_autodiff);
    EXPECT_LT(Relative(r_analytic, r_autodiff), 1e-12);
    EXPECT_LT(Relative(J_analytic[0], J_autodiff[0]), 1e-8);
    EXPECT_LT(Relative(J_analytic[0], NumericBlockJacobian(analytic, {q.data()}, 0)), 1e-5);
    const auto along_tangent = [&](const Eigen::VectorXd& dphi) {
      return Eigen::VectorXd(prior.Residual(rotation * SO3d::Exp(Eigen::Vector3d(dphi))));
    };
    const Eigen::MatrixXd numeric = NumericJacobian(along_tangent, Eigen::VectorXd::Zero(3));
    EXPECT_LT(Relative(Eigen::MatrixXd(prior.Jacobian(rotation)), numeric), 1e-5);
  }
}

}  // namespace
}  // namespace radargauss
