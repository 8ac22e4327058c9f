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

#include "radargauss/experiment/experiment.hpp"
#include "radargauss/lie/manifold.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/core/sh.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "radargauss/residuals/geometric_residual.hpp"
#include "radargauss/residuals/loss.hpp"
#include "radargauss/residuals/rcs_likelihood.hpp"
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

// The Swerling likelihoods and the confidence weight (rcs_likelihood.hpp)
// on every form of the RCS residual: the value is w g_k(a r + b) of the
// paper's residual r, computed here by hand, and the analytic Jacobians
// equal autodiff and central differences, on both sides of the series'
// threshold at z = 1e-3.
TEST_P(JacobianTest, RcsLikelihoodsAnalyticAutodiffNumeric) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int trial = 0; trial < 24; ++trial) {
    RcsTerm term = RandomRcsTerm(rng, GetParam());
    term.degree = trial % (kMaxShDegree + 1);
    term.measurement = 2.0 * uniform(rng) - 1.0;
    Eigen::Vector4d q = SO3d::Exp(0.5 * RandomUnitVector(rng)).quaternion().coeffs();
    Eigen::Vector3d t = RandomUnitVector(rng);
    const Eigen::Vector3d mean_radar = Eigen::Map<const Eigen::Quaterniond>(q.data()).conjugate() * (term.mean - t);
    term.facing = FacingSign(IncidenceVector(term.incidence, term.point_radar, mean_radar));
    double d_norm = 0.0;
    const Eigen::Vector3d d = RcsDirection<double>(term, mean_radar, d_norm);
    const double decibel = term.measurement - EvaluateSh(term.degree, term.coefficients.data(), d);
    term.shape = trial % 2 == 0 ? 1.0 : 2.0;
    term.log_scale = 0.2302585 * (2.0 + 6.0 * uniform(rng));  // scales of 2-8 dB
    term.weight = 0.3 + 0.7 * uniform(rng);
    // z: well away from 0, then just inside and just outside the series.
    const double z = trial < 8 ? 3.0 * (uniform(rng) - 0.5) : (trial < 16 ? 5e-4 : -2e-3);
    term.log_offset = z - term.log_scale * decibel;
    const double k = term.shape;
    const double by_hand = term.weight * (z < 0 ? -1.0 : 1.0) * std::sqrt(2.0 * k * (std::exp(z) - z - 1.0));
    const RcsCostFunction analytic(term);
    const std::unique_ptr<ceres::CostFunction> autodiff(RcsResidual::Create(term));
    std::vector<Eigen::MatrixXd> ja, jd;
    std::vector<double*> blocks = {q.data(), t.data()};
    const Eigen::VectorXd ra = EvaluateWithJacobians(analytic, blocks, ja);
    EXPECT_NEAR(ra[0], by_hand, 1e-9 * std::max(1.0, std::abs(by_hand))) << "trial " << trial;
    EXPECT_NEAR(EvaluateWithJacobians(*autodiff, blocks, jd)[0], ra[0], 1e-12);
    for (int b = 0; b < 2; ++b) {
      EXPECT_LT(Relative(ja[b], jd[b]), 1e-8) << "block " << b << " trial " << trial;
      EXPECT_LT(Relative(ja[b], NumericBlockJacobian(analytic, blocks, b)), 1e-5) << "block " << b;
    }
    const RcsRotationCostFunction analytic_rotation(term, t);
    const std::unique_ptr<ceres::CostFunction> autodiff_rotation(RcsRotationResidual::Create(term, t));
    blocks = {q.data()};
    EvaluateWithJacobians(analytic_rotation, blocks, ja);
    EvaluateWithJacobians(*autodiff_rotation, blocks, jd);
    EXPECT_LT(Relative(ja[0], jd[0]), 1e-8);
    EXPECT_LT(Relative(ja[0], NumericBlockJacobian(analytic_rotation, blocks, 0)), 1e-5);
    Eigen::VectorXd c(ShCoefficientCount(term.degree));
    for (int i = 0; i < c.size(); ++i) c[i] = term.coefficients[i];
    for (const bool full : {false, true}) {
      const RcsCoefficientCostFunction analytic_c(term, t, full);
      const std::unique_ptr<ceres::CostFunction> autodiff_c(RcsCoefficientResidual::Create(term, t, full));
      blocks = {q.data(), c.data()};
      if (full) blocks.push_back(t.data());
      EXPECT_NEAR(EvaluateWithJacobians(analytic_c, blocks, ja)[0], by_hand, 1e-9 * std::max(1.0, std::abs(by_hand)));
      EvaluateWithJacobians(*autodiff_c, blocks, jd);
      for (std::size_t b = 0; b < blocks.size(); ++b) {
        EXPECT_LT(Relative(ja[b], jd[b]), 1e-8) << "block " << b << " trial " << trial;
        EXPECT_LT(Relative(ja[b], NumericBlockJacobian(analytic_c, blocks, int(b))), 1e-5) << "block " << b;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(BothIncidenceModels, JacobianTest,
                         ::testing::Values(IncidenceModel::kOffset, IncidenceModel::kView));

// g_k(z)^2 / 2 is the Gamma(k) negative log-likelihood k (e^z - z - 1), its
// derivative is continuous across the series' threshold, and it is
// sqrt(k) at 0.
TEST(RcsLikelihoods, SwerlingResidualIsTheNegativeLogLikelihood) {
  for (const double k : {1.0, 2.0}) {
    for (const double z : {-4.0, -0.7, -2e-3, -1e-3, -3e-4, 0.0, 2e-4, 9.99e-4, 1e-3, 0.4, 3.0}) {
      const double r = SwerlingResidual(k, z);
      EXPECT_NEAR(0.5 * r * r, k * (std::exp(z) - z - 1.0), 1e-15 + 1e-12 * r * r) << z;
      EXPECT_TRUE(z == 0.0 ? r == 0.0 : (r > 0.0) == (z > 0.0)) << z;
      const double h = 1e-6;
      const double numeric = (SwerlingResidual(k, z + h) - SwerlingResidual(k, z - h)) / (2.0 * h);
      EXPECT_NEAR(SwerlingResidualDerivative(k, z), numeric, 1e-6) << z;
    }
    EXPECT_NEAR(SwerlingResidualDerivative(k, 0.0), std::sqrt(k), 1e-15);
  }
}

// Over a planted Swerling sample (linear RCS Gamma(k, mean / k)), the
// likelihood's maximum lies at the planted mean (it is the sample's linear
// mean), while the decibel residual's lies at the mean of the dB, 2.5 dB
// (k = 1) or 1.2 dB (k = 2) below it.
TEST(RcsLikelihoods, MaximumOverAPlantedSwerlingSampleIsThePlantedMean) {
  const double planted_db = 10.0;
  for (const RcsLikelihood likelihood : {RcsLikelihood::kSwerling1, RcsLikelihood::kSwerling3}) {
    const double k = SwerlingShape(likelihood);
    std::mt19937 rng(static_cast<unsigned>(k));
    std::gamma_distribution<double> gamma(k, 1.0 / k);
    std::vector<double> db;
    double linear_sum = 0.0;
    for (int i = 0; i < 100000; ++i) {
      const double sigma = std::pow(10.0, planted_db / 10.0) * gamma(rng);
      linear_sum += sigma;
      db.push_back(10.0 * std::log10(sigma));
    }
    const double sample_mean_db = 10.0 * std::log10(linear_sum / double(db.size()));
    // The argmin of a cost over the mean (dB): a 0.05 dB grid, then 0.002 dB around its best.
    const auto argmin = [&](const auto& cost) {
      double best_m = 0.0, best = std::numeric_limits<double>::infinity();
      for (double m = planted_db - 4.0; m <= planted_db + 2.0; m += 0.05) {
        if (const double f = cost(m); f < best) best = f, best_m = m;
      }
      const double coarse = best_m;
      for (double m = coarse - 0.06; m <= coarse + 0.06; m += 0.002) {
        if (const double f = cost(m); f < best) best = f, best_m = m;
      }
      return best_m;
    };
    const double best_db = argmin([&](double m) {
      double nll = 0.0;
      for (const double x : db) {
        const double r = SwerlingResidual(k, 0.23025850929940458 * (x - m));
        nll += 0.5 * r * r;
      }
      return nll;
    });
    const double best_decibel_db = argmin([&](double m) {
      double squares = 0.0;
      for (const double x : db) squares += (x - m) * (x - m);
      return squares;
    });
    EXPECT_NEAR(best_db, sample_mean_db, 0.006) << ToString(likelihood);
    EXPECT_NEAR(best_db, planted_db, 0.06) << ToString(likelihood);
    // E[10 log10 X] for X ~ Gamma(k, 1/k): 10 / ln(10) (psi(k) - ln k).
    const double log_bias_db = k == 1.0 ? -2.5068 : -1.1742;
    EXPECT_NEAR(best_decibel_db, planted_db + log_bias_db, 0.06) << ToString(likelihood);
    // The likelihood's own spread: the std of 10 log10 X.
    double mean = 0.0, variance = 0.0;
    for (const double x : db) mean += x / double(db.size());
    for (const double x : db) variance += (x - mean) * (x - mean) / double(db.size());
    EXPECT_NEAR(std::sqrt(variance), RcsLikelihoodSpreadDb(likelihood), 0.05) << ToString(likelihood);
  }
}

// The confidence: 1 while the predictive variance is within the expected,
// then the ratio, by hand; falls as the spread grows (to zero) and as the
// members become fewer; zero without a model.
TEST(RcsLikelihoods, ConfidenceGoesToZeroAsTheSpreadGrows) {
  EXPECT_EQ(RcsConfidence(1.0, 3, 100, 3.0), 1.0);
  // 3 members, constant model, 6 dB: 9 / (36 (1 + 1/3)) = 0.1875.
  EXPECT_NEAR(RcsConfidence(6.0, 0, 3, 3.0), 0.1875, 1e-15);
  double previous = 1.0;
  for (double spread = 3.0; spread < 1e4; spread *= 1.5) {
    const double confidence = RcsConfidence(spread, 2, 20, 3.0);
    EXPECT_LT(confidence, previous) << spread;
    EXPECT_GT(confidence, 0.0);
    previous = confidence;
  }
  EXPECT_LT(previous, 1e-6);
  EXPECT_LT(RcsConfidence(6.0, 3, 17, 3.0), RcsConfidence(6.0, 3, 170, 3.0));
  EXPECT_EQ(RcsConfidence(6.0, -1, 17, 3.0), 0.0);
  EXPECT_THROW(RcsLikelihoodFromString("swerling2"), std::invalid_argument);
  EXPECT_EQ(RcsLikelihoodFromString(ToString(RcsLikelihood::kSwerling3)), RcsLikelihood::kSwerling3);
}

// The map's view information and its weight, by hand: a degree-3 model of
// full confidence counts 15/15, a degree-1 one 3/15, a constant one 0, a
// Gaussian without a model nothing.
TEST(RcsLikelihoods, WeightFromTheMapByHand) {
  GaussianMap map;
  const auto add = [&](int degree, double spread_db, std::uint32_t inliers) {
    Gaussian g;
    g.rcs.degree = degree;
    g.rcs.scale = 1.0;
    g.rcs.spread_db = spread_db;
    g.rcs.inliers = inliers;
    g.rcs.explained = 0.5;
    map.gaussians.push_back(g);
  };
  add(1, 0.5, 400);  // confidence 1
  add(0, 0.5, 400);
  add(-1, 0.0, 0);
  RcsTermOptions options;  // decibel: expected spread 2 dB
  RcsMapSummary summary = SummariseRcs(map, options);
  EXPECT_EQ(summary.models, 2u);
  EXPECT_NEAR(summary.view_information, 0.5 * 3.0 / 15.0, 1e-15);
  EXPECT_NEAR(summary.mean_confidence, 1.0, 1e-15);
  EXPECT_NEAR(RcsWeightFromMap(summary), kRcsWeightPerInformation * 0.1, 1e-15);
  // A degree-3 model whose spread is 4x the expected: confidence 1 / (16 (1 + 16/400)).
  add(3, 8.0, 400);
  summary = SummariseRcs(map, options);
  const double confidence = 1.0 / (16.0 * (1.0 + 16.0 / 400.0));
  EXPECT_NEAR(summary.view_information, (0.2 + confidence) / 3.0, 1e-15);
  EXPECT_NEAR(summary.median_spread_db, 0.5, 1e-15);
  // Every model of degree 3 at full confidence: capped at kMaxChosenRcsWeight.
  for (Gaussian& g : map.gaussians) g.rcs.degree = 3, g.rcs.spread_db = 0.1;
  EXPECT_EQ(RcsWeightFromMap(SummariseRcs(map, options)), kMaxChosenRcsWeight);
  EXPECT_EQ(RcsWeightFromMap(SummariseRcs(GaussianMap{}, options)), 0.0);
}

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
