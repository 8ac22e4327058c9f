// SPDX-License-Identifier: BSD-3-Clause
// The front door (radargauss.hpp): BuildMap is the map pipeline, Match is
// the named solver, a MatchingMap keeps its map alive, and a result's
// information matrix is eq. 2's Gauss-Newton matrix (central differences).
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "radargauss/radargauss.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "support/scan_matching_fixtures.hpp"

namespace radargauss {
namespace {

void ExpectSameMaps(const GaussianMap& a, const GaussianMap& b) {
  ASSERT_EQ(a.gaussians.size(), b.gaussians.size());
  EXPECT_EQ(a.incidence, b.incidence);
  for (std::size_t i = 0; i < a.gaussians.size(); ++i) {
    const Gaussian &x = a.gaussians[i], &y = b.gaussians[i];
    EXPECT_EQ(x.mean, y.mean) << i;
    EXPECT_EQ(x.covariance, y.covariance) << i;
    EXPECT_EQ(x.point_count, y.point_count) << i;
    EXPECT_EQ(x.rcs.degree, y.rcs.degree) << i;
    EXPECT_EQ(x.rcs.median, y.rcs.median) << i;
    EXPECT_EQ(x.rcs.scale, y.rcs.scale) << i;
    EXPECT_EQ(x.rcs.coefficients, y.rcs.coefficients) << i;
  }
}

// BuildMap is the three stages written out (cloud, Gaussians, RCS models),
// from a sequence or from its scans and poses.
TEST(FrontDoor, BuildMapIsTheMapPipeline) {
  SimulationConfig config;
  config.scans = 30;
  const Sequence sequence = AsSequence(Simulate(config));
  MapOptions options;
  options.rcs.incidence = IncidenceModel::kView;
  options.rcs.max_degree = 2;
  const MapCloud cloud = BuildMapCloud(sequence);
  GaussianMap expected;
  std::vector<int> association;
  expected.gaussians = BuildGaussians(cloud.points, options.gaussians, {}, &association);
  FitRcsModels(expected, cloud, association, options.rcs);
  ASSERT_GT(expected.gaussians.size(), 100u);
  ExpectSameMaps(BuildMap(sequence, options), expected);
  ExpectSameMaps(BuildMap(sequence.scans, sequence.poses, options), expected);
  EXPECT_THROW(BuildMap(sequence.scans, {}, options), DataError);
}

// InertialOdometry and Slam are the classes run over every scan, bit for bit.
TEST(FrontDoor, InertialOdometryAndSlamAreTheirClassesRunOverTheSequence) {
  SimulationConfig config;
  config.scans = 40;
  config.imu_rate_hz = 200.0;
  const SimulatedSequence simulated = Simulate(config);
  const Sequence sequence = AsSequence(simulated);
  const RadarOdometry inertial = InertialOdometry(sequence, simulated.imu, simulated.radar_from_imu);
  ASSERT_NE(InertialMotionOf(inertial), nullptr);
  RadarOdometry by_hand(OdometryOptions{}, std::make_unique<InertialMotion>(RadarInertialOptions{},
                                                                            simulated.radar_from_imu, simulated.imu));
  for (const RadarScan& scan : sequence.scans) by_hand.Register(scan);
  ASSERT_EQ(inertial.steps().size(), sequence.scans.size());
  for (std::size_t k = 0; k < sequence.scans.size(); ++k) {
    EXPECT_EQ(inertial.steps()[k].pose.translation(), by_hand.steps()[k].pose.translation());
  }
  EXPECT_THROW(InertialOdometry(sequence, {}, simulated.radar_from_imu), DataError);

  SlamOptions options;
  options.submap_distance = 5.0;
  const auto slam = Slam(sequence, options);
  RadarSlam slam_by_hand(options);
  for (const RadarScan& scan : sequence.scans) slam_by_hand.Register(scan);
  slam_by_hand.Finish();
  const std::vector<SE3d> poses = slam->Poses(), expected = slam_by_hand.Poses();
  ASSERT_EQ(poses.size(), sequence.scans.size());
  EXPECT_GT(slam->keyframes().size(), 2u);
  for (std::size_t k = 0; k < poses.size(); ++k) EXPECT_EQ(poses[k].translation(), expected[k].translation());
}

// Match with a solver kind is that solver's match, bit for bit.
TEST(FrontDoor, MatchIsTheNamedSolver) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const SE3d initial = Perturbed(world.simulated.ground_truth[kTestScan].pose, 0.5, 2.0, 3);
  for (const std::string& name : ScanMatcherNames()) {
    MatchOptions options;
    options.solver = SolverKindFromString(name);
    options.matching.w_rcs = 0.25;
    EXPECT_EQ(ToString(options.solver), name);
    const ScanMatchingResult front = Match(scan, *world.matching, initial, options);
    const ScanMatchingResult direct = MakeScanMatcher(name, options.matching)->Match(scan, *world.matching, initial);
    EXPECT_TRUE(SamePose(front.pose, direct.pose)) << name;
    EXPECT_EQ(front.iterations, direct.iterations) << name;
    EXPECT_EQ(front.information, direct.information) << name;
  }
  EXPECT_THROW(SolverKindFromString("lm"), std::invalid_argument);
}

// A MatchingMap made from a temporary keeps the map (ASan would report a
// dangling reference); one made from a shared pointer shares it.
TEST(FrontDoor, MatchingMapKeepsItsMap) {
  const World& world = SimulatedWorld();
  const MatchingMap owned(GaussianMap(world.map));
  EXPECT_EQ(owned.map().gaussians.size(), world.map.gaussians.size());
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  const ScanMatchingResult result = Match(world.simulated.scans[kTestScan], owned, Perturbed(truth, 0.3, 1.0, 1));
  double dt = 0.0, dr = 0.0;
  PoseErrors(result.pose, truth, dt, dr);
  EXPECT_LT(dt, 0.05);
  auto shared = std::make_shared<const GaussianMap>(world.map);
  const MatchingMap sharing(shared);
  EXPECT_EQ(&sharing.map(), shared.get());
  EXPECT_EQ(shared.use_count(), 2);
  EXPECT_THROW(MatchingMap(std::shared_ptr<const GaussianMap>()), std::invalid_argument);
}

// The residuals of fixed correspondences at pose (+) [dt; dphi], stacked:
// geometric L^T e, then RCS with the association's translation.
Eigen::VectorXd StackedResiduals(const Correspondences& c, const SE3d& pose, const Eigen::VectorXd& d) {
  const SE3d moved(pose.rotation() * SO3d::Exp(d.tail<3>()), pose.translation() + d.head<3>());
  Eigen::VectorXd r(3 * c.geometric.size() + c.rcs.size());
  const Eigen::Matrix3d R = moved.rotation().Matrix();
  for (std::size_t k = 0; k < c.geometric.size(); ++k) {
    const GeometricTerm& term = c.geometric[k];
    const Eigen::Vector3d e = R * term.point_radar + moved.translation() - c.index->Mean(term.gaussian);
    r.segment<3>(3 * k) = c.index->SqrtInformationT(term.gaussian) * e;
  }
  for (std::size_t k = 0; k < c.rcs.size(); ++k) {
    const RcsTerm& term = c.rcs[k];
    const Eigen::Vector3d mean_radar = R.transpose() * (term.mean - c.pose.translation());
    r[3 * c.geometric.size() + k] = RcsResidualAt<double>(term, mean_radar, term.coefficients.data());
  }
  return r;
}

// With trivial losses: (1-w)/N_geo J_geo^T J_geo + w/N_rcs J_rcs^T J_rcs from
// central differences; the RCS rows have no translation columns.
TEST(Information, IsTheGaussNewtonMatrixOfEq2) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const SE3d pose = Perturbed(world.simulated.ground_truth[kTestScan].pose, 0.05, 0.3, 2);
  const Correspondences c = FindCorrespondences(scan, *world.exact, 0, pose, 3.0, true);
  ASSERT_GT(c.geometric.size(), 100u);
  ASSERT_GT(c.rcs.size(), 50u);
  ScanMatchingOptions options;
  options.w_rcs = 0.25;
  options.rcs_loss = {LossType::kTrivial, 1.0};
  const Eigen::MatrixXd J =
      NumericJacobian([&](const Eigen::VectorXd& d) { return StackedResiduals(c, pose, d); }, Eigen::VectorXd::Zero(6));
  const std::size_t n_geo = c.geometric.size(), n_rcs = c.rcs.size();
  const Eigen::MatrixXd J_geo = J.topRows(3 * n_geo), J_rcs = J.bottomRows(n_rcs);
  EXPECT_LT(J_rcs.leftCols<3>().norm(), 1e-9);
  const Eigen::MatrixXd expected = (1.0 - options.w_rcs) / double(n_geo) * J_geo.transpose() * J_geo +
                                   options.w_rcs / double(n_rcs) * J_rcs.transpose() * J_rcs;
  const Eigen::Matrix<double, 6, 6> information = InformationMatrix(c, pose, options);
  EXPECT_LT(Relative(information, expected), 1e-6);
  options.w_rcs = 0.0;
  EXPECT_LT(Relative(InformationMatrix(c, pose, options), J_geo.transpose() * J_geo / double(n_geo)), 1e-6);
}

// Every solver's result carries it at the final pose and association
// (re-associating at every step, the final association is made there).
TEST(Information, ResultCarriesItAtTheFinalPose) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const SE3d initial = Perturbed(world.simulated.ground_truth[kTestScan].pose, 1.0, 3.0, 4);
  for (const std::string& name : ScanMatcherNames()) {
    ScanMatchingOptions options;
    options.w_rcs = 0.25;
    options.reassociation_translation = 0.0;
    options.reassociation_rotation = 0.0;
    const ScanMatchingResult result = MakeScanMatcher(name, options)->Match(scan, *world.matching, initial);
    ASSERT_TRUE(result.converged) << name << ": " << result.reason;
    const Correspondences final_c =
        FindCorrespondences(scan, *world.matching, world.matching->levels() - 1, result.pose, options.gate, true);
    // (gn-autodiff forms it with Jets: the same to rounding)
    EXPECT_LT(Relative(result.information, InformationMatrix(final_c, result.pose, options)), 1e-12) << name;
    using Eigen6 = Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>;
    EXPECT_GT(Eigen6(result.information).eigenvalues().minCoeff(), 0.0) << name;
  }
  RadarScan empty;
  EXPECT_TRUE(Match(empty, *world.matching, initial).information.isZero(0.0));
}

}  // namespace
}  // namespace radargauss
