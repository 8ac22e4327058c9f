// SPDX-License-Identifier: BSD-3-Clause
// The Doppler velocity term in scan matching: eq. 2 plus weight |r_v|^2 in
// the cost, the normal equations (against central differences of the cost)
// and both solvers, which reach the same optimum and follow a strong term.
#include <gtest/gtest.h>

#include "support/scan_matching_fixtures.hpp"

namespace radargauss {
namespace {

// A prior that puts the scan at `target` (rotation of `previous` held).
VelocityPrior PriorTowards(const SE3d& previous, const Eigen::Vector3d& target, double weight) {
  VelocityPrior prior;
  prior.previous = previous;
  prior.displacement = previous.rotation().Inverse() * (target - previous.translation());
  prior.sqrt_information = Eigen::Vector3d(10.0, 20.0, 5.0).asDiagonal();
  prior.weight = weight;
  return prior;
}

TEST(VelocityTerm, EntersTheCostAndTheNormalEquations) {
  const World& world = SimulatedWorld();
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  const SE3d pose = Perturbed(truth, 0.2, 0.5, 4);
  const Correspondences c = FindCorrespondences(world.simulated.scans[kTestScan], *world.exact, 0, pose, 3.0, true);
  ScanMatchingOptions plain;
  plain.w_rcs = 0.25;
  ScanPriors with;
  with.velocity = PriorTowards(Perturbed(truth, 1.0, 2.0, 5), truth.translation(), 0.01);
  const Eigen::Vector3d r = with.velocity->Residual(pose.translation());
  EXPECT_NEAR(EvaluateCost(c, pose, plain, with), EvaluateCost(c, pose, plain, {}) + 0.01 * r.squaredNorm(), 1e-12);
  // g = sum w J^T r is half the cost's gradient: the term's part by central differences.
  const auto term_cost = [&](const Eigen::VectorXd& dt) {
    const SE3d moved(pose.rotation(), pose.translation() + dt);
    return Eigen::VectorXd::Constant(1, EvaluateCost(c, moved, plain, with) - EvaluateCost(c, moved, plain, {}));
  };
  const Eigen::VectorXd gradient = NumericJacobian(term_cost, Eigen::VectorXd::Zero(3)).transpose();
  const CombinedSystem a = BuildCombinedSystem(c, pose, plain, {}), b = BuildCombinedSystem(c, pose, plain, with);
  EXPECT_LT(((b.g - a.g).segment<3>(kTranslationOffset) - 0.5 * gradient).norm(), 1e-6 * gradient.norm());
  const Eigen::Matrix3d J = with.velocity->Jacobian();
  const Eigen::Matrix<double, 6, 6> added = b.H - a.H;
  const Eigen::Matrix3d expected = 0.01 * J.transpose() * J;
  const Eigen::Matrix3d translation_block = added.topLeftCorner(3, 3);  // kTranslationOffset = 0
  const Eigen::Matrix3d rotation_block = added.bottomRightCorner(3, 3);
  EXPECT_LT((translation_block - expected).norm(), 1e-9);
  EXPECT_LT(rotation_block.norm(), 1e-12);
  EXPECT_NEAR(b.cost - a.cost, 0.01 * r.squaredNorm(), 1e-12);
}

// Both solvers on one association (no re-association, tight tolerances)
// reach the same optimum with the term; a strong term pulls the translation
// to its target; weight 0 changes nothing; the result keeps the term's matrix.
TEST(VelocityTerm, SolversAgreeAndFollowAStrongTerm) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  const SE3d initial = Perturbed(truth, 0.1, 0.3, 6);
  ScanMatchingOptions options = OneAssociationToConvergence();
  const Eigen::Vector3d target = truth.translation() + Eigen::Vector3d(0.3, -0.2, 0.1);
  ScanPriors priors;
  priors.velocity = PriorTowards(Perturbed(truth, 1.0, 1.0, 7), target, 0.05);
  const ScanMatchingResult gn = MakeSolver("gn", options)->Match(scan, *world.exact, initial, priors);
  const ScanMatchingResult lm = CeresSolver(options, CeresToItsOptimum()).Match(scan, *world.exact, initial, priors);
  ASSERT_TRUE(gn.converged) << gn.reason;
  ASSERT_TRUE(lm.converged) << lm.reason;
  ExpectPoseNear(gn.pose, lm.pose, 1e-4, 1e-4, "gn against ceres with the velocity term");
  const Eigen::Matrix3d J = priors.velocity->Jacobian();
  const Eigen::Matrix3d expected = 0.05 * J.transpose() * J;
  const Eigen::Matrix3d kept = gn.velocity_information.topLeftCorner(3, 3);
  EXPECT_LT((kept - expected).norm(), 1e-9);
  priors.velocity->weight = 1e4;
  for (const std::string name : {"gn", "ceres"}) {
    const ScanMatchingResult strong = MakeSolver(name, options)->Match(scan, *world.exact, initial, priors);
    EXPECT_LT((strong.pose.translation() - target).norm(), 0.01) << name;
  }
  priors.velocity->weight = 0.0;
  const ScanMatchingResult off = MakeSolver("gn", options)->Match(scan, *world.exact, initial, priors);
  priors.velocity.reset();
  EXPECT_TRUE(SamePose(off.pose, MakeSolver("gn", options)->Match(scan, *world.exact, initial, priors).pose));
}

}  // namespace
}  // namespace radargauss
