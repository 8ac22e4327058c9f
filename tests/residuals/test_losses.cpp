// SPDX-License-Identifier: BSD-3-Clause
// The robust losses: derivatives and the LossSum the solvers accumulate with.

#include <ceres/cost_function.h>
#include <ceres/crs_matrix.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <algorithm>
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
#include "radargauss/residuals/robust_loss.hpp"
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

TEST(Losses, GemanMcClureDerivativesAndFactory) {
  const GemanMcClureLoss loss(0.7);
  for (const double s : {0.1, 1.0, 5.0}) {
    double rho[3], plus[3], minus[3];
    loss.Evaluate(s, rho);
    loss.Evaluate(s + 1e-6, plus);
    loss.Evaluate(s - 1e-6, minus);
    const double h = 2e-6;
    EXPECT_NEAR(rho[1], (plus[0] - minus[0]) / h, 1e-6);
    EXPECT_NEAR(rho[2], (plus[1] - minus[1]) / h, 1e-5);
  }
  for (const char* name : {"trivial", "huber", "cauchy", "geman-mcclure", "tukey"}) {
    LossSum robust({LossTypeFromString(name), 1.0});
    EXPECT_NEAR(robust.Add(1e-9), 1.0, 1e-6) << name;  // rho'(0) = 1 for every loss
    EXPECT_LE(robust.Add(100.0), 1.0) << name;
  }
  EXPECT_THROW(LossTypeFromString("l7"), std::invalid_argument);
}

// Dynamic covariance scaling: rho' and rho'' against central differences on
// both sides of Phi, continuous at Phi, and rho' the square of DCS's scale
// min(1, 2 Phi / (Phi + s)) (Agarwal et al. 2013).
TEST(Losses, DcsDerivativesAndScale) {
  const double a = 1.5, phi = a * a;
  const DcsLoss loss(a);
  for (const double s : {0.5, 2.0, phi + 0.1, 10.0, 1e4}) {
    double rho[3], plus[3], minus[3];
    loss.Evaluate(s, rho);
    loss.Evaluate(s + 1e-6, plus);
    loss.Evaluate(s - 1e-6, minus);
    EXPECT_NEAR(rho[1], (plus[0] - minus[0]) / 2e-6, 1e-6) << s;
    EXPECT_NEAR(rho[2], (plus[1] - minus[1]) / 2e-6, 1e-5) << s;
    const double scale = std::min(1.0, 2.0 * phi / (phi + s));
    EXPECT_NEAR(rho[1], scale * scale, 1e-12) << s;
  }
  double below[3], above[3];
  loss.Evaluate(phi * (1.0 - 1e-12), below);
  loss.Evaluate(phi * (1.0 + 1e-12), above);
  EXPECT_NEAR(below[0], above[0], 1e-9);
  EXPECT_NEAR(below[1], above[1], 1e-9);
  EXPECT_EQ(LossTypeFromString("dcs"), LossType::kDcs);
}

// LossSum against the loss classes term by term (Cauchy's product of logs
// included): squared residuals from 0 to 1e307, so that the product is
// renormalised many times, and then single factors pass 2^500 (1e307 would
// overflow the product unless it is below 2^4).
TEST(Losses, LossSumMatchesTheLossClasses) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> exponent(-12.0, 3.0);
  std::vector<double> squared_norms = {0.0, 1e-300, 1.0};
  for (int k = 0; k < 20000; ++k) squared_norms.push_back(std::pow(10.0, exponent(rng)));
  for (const double s : {1e160, 1e307, 1.0, 1e307}) squared_norms.push_back(s);
  for (const LossType type : {LossType::kTrivial, LossType::kHuber, LossType::kCauchy, LossType::kGemanMcClure,
                              LossType::kTukey, LossType::kDcs}) {
    for (const double scale : {0.3, 1.0, 2.5}) {
      const std::unique_ptr<ceres::LossFunction> reference(MakeLoss({type, scale}));
      LossSum sum({type, scale});
      double rho_sum = 0.0;
      for (const double s : squared_norms) {
        double rho[3] = {s, 1.0, 0.0};  // trivial (no loss object)
        if (reference) reference->Evaluate(s, rho);
        double second = -1.0;
        EXPECT_EQ(sum.Add(s, &second), rho[1]) << ToString(type) << " s = " << s;
        EXPECT_EQ(second, rho[2]) << ToString(type) << " s = " << s;
        rho_sum += rho[0];
      }
      EXPECT_NEAR(sum.Sum(), rho_sum, 1e-13 * rho_sum) << ToString(type) << " scale " << scale;
    }
  }
  // Non-finite squared residuals give a non-finite sum, as the sum of rho would.
  LossSum infinite({LossType::kCauchy, 1.0}), not_a_number({LossType::kCauchy, 1.0});
  infinite.Add(1.0);
  infinite.Add(std::numeric_limits<double>::infinity());
  EXPECT_EQ(infinite.Sum(), std::numeric_limits<double>::infinity());
  not_a_number.Add(std::numeric_limits<double>::quiet_NaN());
  not_a_number.Add(1.0);
  EXPECT_TRUE(std::isnan(not_a_number.Sum()));
  for (const LossType type : {LossType::kCauchy, LossType::kHuber}) {
    EXPECT_THROW(LossSum({type, 0.0}), std::invalid_argument) << ToString(type);
  }
}

}  // namespace
}  // namespace radargauss
