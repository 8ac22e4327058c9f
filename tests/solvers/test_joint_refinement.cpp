// SPDX-License-Identifier: BSD-3-Clause
// Joint refinement of poses and SH coefficients.

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

#include "radargauss/core/error.hpp"
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

// Joint refinement on a simulated sequence with perturbed poses lowers both
// the pose error and the RCS residual RMS.
TEST(JointRefinement, LowersPoseErrorAndRcsResidual) {
  const World& world = SimulatedWorld();
  std::vector<RadarScan> scans;
  std::vector<SE3d> truth, perturbed;
  for (int k = 20; k < 60; k += 2) {
    scans.push_back(world.simulated.scans[k]);
    truth.push_back(world.simulated.ground_truth[k].pose);
    perturbed.push_back(truth.size() == 1 ? truth.back() : Perturbed(truth.back(), 0.15, 0.5, std::uint32_t(k)));
  }
  const auto mean_error = [&](const std::vector<SE3d>& poses, double& translation, double& rotation_deg) {
    translation = rotation_deg = 0.0;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      double dt = 0.0, dr = 0.0;
      PoseErrors(poses[k], truth[k], dt, dr);
      translation += dt / poses.size();
      rotation_deg += dr / poses.size();
    }
  };
  JointRefinementOptions options;
  options.matching.w_rcs = 0.25;
  options.coefficient_prior = 1.0;  // coefficients seen by few residuals stay put
  options.threads = 2;
  JointRefinementResult schur_result;
  for (const bool schur : {true, false}) {
    options.schur = schur;
    const JointRefinementResult result = RefineJointly(scans, perturbed, world.map, options);
    if (schur) schur_result = result;
    double t0 = 0.0, r0 = 0.0, t1 = 0.0, r1 = 0.0;
    mean_error(perturbed, t0, r0);
    mean_error(result.poses, t1, r1);
    const double rms0 = RcsResidualRms(scans, perturbed, world.map, 3.0);
    const double rms1 = RcsResidualRms(scans, result.poses, result.map, 3.0);
    std::printf(
        "joint refinement (%s, %zu scans): pose error %.3f m / %.3f deg -> %.3f m / %.3f deg; "
        "RCS residual RMS %.4f -> %.4f; %d iterations, %.0f ms\n",
        schur ? "SPARSE_SCHUR" : "SPARSE_NORMAL_CHOLESKY", scans.size(), t0, r0, t1, r1, rms0, rms1, result.iterations,
        result.time_ms);
    EXPECT_LT(t1, 0.5 * t0);
    EXPECT_LT(r1, r0);
    EXPECT_LT(rms1, rms0);
    EXPECT_EQ(result.poses[0].translation(), perturbed[0].translation());  // gauge
    EXPECT_LT(result.final_cost, result.initial_cost);
  }
  // The autodiff RCS blocks (Jets through RcsCoefficientResidual) reach the
  // analytic twin's poses and coefficients.
  options.schur = true;
  options.matching.jacobians = JacobianMode::kAutoDiff;
  const JointRefinementResult autodiff = RefineJointly(scans, perturbed, world.map, options);
  EXPECT_EQ(autodiff.iterations, schur_result.iterations);
  for (std::size_t k = 0; k < scans.size(); ++k) {
    double dt = 0.0, dr = 0.0;
    PoseErrors(autodiff.poses[k], schur_result.poses[k], dt, dr);
    EXPECT_LT(dt, 1e-6) << k;
    EXPECT_LT(dr, 1e-5) << k;  // deg
  }
  double largest_coefficient_change = 0.0, largest_difference = 0.0;
  for (std::size_t g = 0; g < world.map.gaussians.size(); ++g) {
    for (int i = 0; i < ShCoefficientCount(kMaxShDegree); ++i) {
      const double analytic = schur_result.map.gaussians[g].rcs.coefficients[i];
      largest_coefficient_change =
          std::max(largest_coefficient_change, std::abs(analytic - world.map.gaussians[g].rcs.coefficients[i]));
      largest_difference =
          std::max(largest_difference, std::abs(autodiff.map.gaussians[g].rcs.coefficients[i] - analytic));
    }
  }
  EXPECT_GT(largest_coefficient_change, 1e-3);  // the coefficients did move
  EXPECT_LT(largest_difference, 1e-6);
  EXPECT_THROW(RefineJointly(scans, {}, world.map, JointRefinementOptions{}), std::invalid_argument);
}

// A map of another place (the same map 1 km away) is refused before any
// work, with the share it found; the real map passes the same check.
TEST(JointRefinement, RefusesAMapTheScansDoNotLieOn) {
  const World& world = SimulatedWorld();
  const std::vector<RadarScan> scans(world.simulated.scans.begin() + 20, world.simulated.scans.begin() + 24);
  std::vector<SE3d> poses;
  for (int k = 20; k < 24; ++k) poses.push_back(world.simulated.ground_truth[k].pose);
  GaussianMap elsewhere = world.map;
  for (Gaussian& g : elsewhere.gaussians) g.mean.x() += 1000.0;
  JointRefinementOptions options;
  options.rounds = 1;
  options.max_iterations_per_round = 1;
  try {
    RefineJointly(scans, poses, elsewhere, options);
    ADD_FAILURE() << "a map 1 km away was refined";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("0.0 % of the scans' points lie near the map"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(RefineJointly(scans, poses, world.map, options));
  options.min_associated_share = 0.0;  // the check off
  EXPECT_NO_THROW(RefineJointly(scans, poses, elsewhere, options));
  options.min_associated_share = 1.5;
  EXPECT_THROW(RefineJointly(scans, poses, world.map, options), std::invalid_argument);
}

}  // namespace
}  // namespace radargauss
