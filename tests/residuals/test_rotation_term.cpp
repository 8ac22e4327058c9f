// SPDX-License-Identifier: BSD-3-Clause
// The rotation term in scan matching: eq. 2 plus weight |r_w|^2 in the cost,
// the normal equations (against central differences of the cost along the
// right perturbation) and both solvers, which reach the same optimum and
// follow a strong term; and in odometry, the tilt it holds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "support/scan_matching_fixtures.hpp"

namespace radargauss {
namespace {

RotationPrior PriorAt(const SO3d& predicted, double weight) {
  RotationPrior prior;
  prior.predicted = predicted;
  prior.sqrt_information = Eigen::Vector3d(100.0, 50.0, 10.0).asDiagonal();
  prior.weight = weight;
  return prior;
}

TEST(RotationTerm, EntersTheCostAndTheNormalEquations) {
  const World& world = SimulatedWorld();
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  const SE3d pose = Perturbed(truth, 0.2, 0.5, 4);
  const Correspondences c = FindCorrespondences(world.simulated.scans[kTestScan], *world.exact, 0, pose, 3.0, true);
  ScanMatchingOptions plain;
  plain.w_rcs = 0.25;
  ScanPriors with;
  with.rotation = PriorAt(Perturbed(truth, 0.0, 3.0, 5).rotation(), 0.01);
  const Eigen::Vector3d r = with.rotation->Residual(pose.rotation());
  EXPECT_NEAR(EvaluateCost(c, pose, plain, with), EvaluateCost(c, pose, plain, {}) + 0.01 * r.squaredNorm(), 1e-12);
  // g = sum w J^T r is half the cost's gradient along R Exp(dphi).
  const auto term_cost = [&](const Eigen::VectorXd& dphi) {
    const SE3d moved(pose.rotation() * SO3d::Exp(Eigen::Vector3d(dphi)), pose.translation());
    return Eigen::VectorXd::Constant(1, EvaluateCost(c, moved, plain, with) - EvaluateCost(c, moved, plain, {}));
  };
  const Eigen::VectorXd gradient = NumericJacobian(term_cost, Eigen::VectorXd::Zero(3)).transpose();
  const CombinedSystem a = BuildCombinedSystem(c, pose, plain, {}), b = BuildCombinedSystem(c, pose, plain, with);
  EXPECT_LT(((b.g - a.g).segment<3>(kRotationOffset) - 0.5 * gradient).norm(), 1e-6 * gradient.norm());
  const Eigen::Matrix3d J = with.rotation->Jacobian(pose.rotation());
  const Eigen::Matrix<double, 6, 6> added = b.H - a.H;
  const Eigen::Matrix3d rotation_block = added.block<3, 3>(kRotationOffset, kRotationOffset);
  EXPECT_LT((rotation_block - 0.01 * J.transpose() * J).norm(), 1e-9);
  const Eigen::Matrix3d translation_block = added.block<3, 3>(kTranslationOffset, kTranslationOffset);
  EXPECT_LT(translation_block.norm(), 1e-12);
  EXPECT_NEAR(b.cost - a.cost, 0.01 * r.squaredNorm(), 1e-12);
}

// Both solvers on one association reach the same optimum with the term; a
// strong term pulls the rotation to its prediction; weight 0 changes nothing.
TEST(RotationTerm, SolversAgreeAndFollowAStrongTerm) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  const SE3d initial = Perturbed(truth, 0.1, 0.3, 6);
  ScanMatchingOptions options = OneAssociationToConvergence();
  const SO3d target = truth.rotation() * SO3d::Exp(Eigen::Vector3d(0.01, -0.02, 0.015));
  ScanPriors priors;
  priors.rotation = PriorAt(target, 1e-4);
  const ScanMatchingResult gn = MakeSolver("gn", options)->Match(scan, *world.exact, initial, priors);
  const ScanMatchingResult lm = CeresSolver(options, CeresToItsOptimum()).Match(scan, *world.exact, initial, priors);
  ASSERT_TRUE(gn.converged) << gn.reason;
  ASSERT_TRUE(lm.converged) << lm.reason;
  ExpectPoseNear(gn.pose, lm.pose, 1e-4, 1e-4, "gn against ceres with the rotation term");
  const Eigen::Matrix3d J = priors.rotation->Jacobian(gn.pose.rotation());
  const Eigen::Matrix3d kept = gn.rotation_information.block<3, 3>(kRotationOffset, kRotationOffset);
  EXPECT_LT((kept - 1e-4 * J.transpose() * J).norm(), 1e-9);
  priors.rotation->weight = 1e4;
  for (const std::string name : {"gn", "ceres"}) {
    const ScanMatchingResult strong = MakeSolver(name, options)->Match(scan, *world.exact, initial, priors);
    EXPECT_LT((target.Inverse() * strong.pose.rotation()).Log().norm(), 1e-3) << name;
  }
  priors.rotation->weight = 0.0;
  const ScanMatchingResult off = MakeSolver("gn", options)->Match(scan, *world.exact, initial, priors);
  priors.rotation.reset();
  EXPECT_TRUE(SamePose(off.pose, MakeSolver("gn", options)->Match(scan, *world.exact, initial, priors).pose));
}

// Roll and pitch of the estimate against the truth's, the worst over a run (deg).
double WorstTilt(const Trajectory& estimate, const Trajectory& truth) {
  double worst = 0.0;
  for (std::size_t k = 0; k < estimate.size(); ++k) {
    const Eigen::Vector3d e = (truth[k].pose.rotation().Inverse() * estimate[k].pose.rotation()).Log();
    worst = std::max(worst, std::hypot(e.x(), e.y()) * 180.0 / M_PI);
  }
  return worst;
}

// On a simulated drive (elevation field of view 15 deg) the term keeps the
// tilt within 3 deg of the truth (2.1 deg; 7.5 without) and halves the
// worst error.
TEST(RotationTerm, HoldsTheTiltOfASimulatedDrive) {
  SimulationConfig config;
  config.scans = 120;  // 12 s, 72 m with a corner
  config.seed = 3;
  const SimulatedSequence drive = Simulate(config);
  const auto run = [&](double weight) {
    OdometryOptions options;
    options.rotation_weight = weight;
    options.initial_pose = drive.ground_truth[0].pose;
    RadarOdometry odometry(options);
    for (const RadarScan& scan : drive.scans) odometry.Register(scan);
    return WorstTilt(odometry.trajectory(), drive.ground_truth);
  };
  const double with = run(1.0), without = run(0.0);
  EXPECT_LT(with, 3.0) << "without the term: " << without << " deg";
  EXPECT_LT(with, 0.5 * without) << "without the term: " << without << " deg";
}

}  // namespace
}  // namespace radargauss
