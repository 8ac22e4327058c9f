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
#include "test_util.hpp"

namespace radargauss {
namespace {

using testing::NumericJacobian;
using testing::RandomUnitVector;

// ---------------------------------------------------------------------------
// Jacobians: analytic twin vs autodiff vs central differences, in the ambient
// parameters (quaternion x y z w, translation).

// Evaluates a cost function with two or one parameter blocks; returns the
// residuals and fills the Jacobians (row-major per block).
Eigen::VectorXd EvaluateWithJacobians(const ceres::CostFunction& cost, const std::vector<double*>& blocks,
                                      std::vector<Eigen::MatrixXd>& jacobians) {
  const int m = cost.num_residuals();
  Eigen::VectorXd residuals(m);
  std::vector<std::vector<double>> storage;
  std::vector<double*> pointers;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    storage.emplace_back(m * cost.parameter_block_sizes()[b]);
    pointers.push_back(storage.back().data());
  }
  EXPECT_TRUE(cost.Evaluate(blocks.data(), residuals.data(), pointers.data()));
  jacobians.clear();
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const int n = cost.parameter_block_sizes()[b];
    jacobians.push_back(Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        storage[b].data(), m, n));
  }
  return residuals;
}

Eigen::MatrixXd NumericBlockJacobian(const ceres::CostFunction& cost, std::vector<double*> blocks, int which) {
  const int n = cost.parameter_block_sizes()[which];
  Eigen::VectorXd x = Eigen::Map<Eigen::VectorXd>(blocks[which], n);
  return NumericJacobian(
      [&](const Eigen::VectorXd& value) {
        Eigen::VectorXd copy = value;
        std::vector<double*> b = blocks;
        b[which] = copy.data();
        Eigen::VectorXd r(cost.num_residuals());
        cost.Evaluate(b.data(), r.data(), nullptr);
        return r;
      },
      x, 1e-6);
}

double Relative(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(1e-12, b.norm());
}

RcsTerm RandomRcsTerm(std::mt19937& rng, IncidenceModel incidence) {
  std::normal_distribution<double> normal;
  RcsTerm term;
  term.point_radar = Eigen::Vector3d(8.0 + normal(rng), 2.0 * normal(rng), normal(rng));
  term.mean = Eigen::Vector3d(3.0 * normal(rng), 3.0 * normal(rng), normal(rng)) + Eigen::Vector3d(10, 0, 0);
  term.measurement = 0.3;
  term.degree = 3;
  for (double& c : term.coefficients) c = 0.5 * normal(rng);
  term.incidence = incidence;
  return term;
}

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
                              LossType::kTukey}) {
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

// ---------------------------------------------------------------------------
// Solvers on a simulated scan against the map of its sequence.

struct World {
  SimulatedSequence simulated;
  GaussianMap map;       // RCS models with the paper's offset incidence
  GaussianMap view_map;  // the same Gaussians, RCS models with view incidence
  std::unique_ptr<MatchingMap> matching;
  std::unique_ptr<MatchingMap> exact;  // the map alone (ExactMapOnly): one association at a time
};

const World& SimulatedWorld() {
  static const World* world = [] {
    auto* w = new World;
    SimulationConfig config;
    config.scans = 80;
    config.seed = 5;
    w->simulated = Simulate(config);
    const MapCloud cloud = BuildMapCloud(AsSequence(w->simulated));
    GaussianMapOptions options;
    std::vector<int> association;
    w->map.gaussians = BuildGaussians(cloud.points, options, {}, &association);
    w->view_map = w->map;
    FitRcsModels(w->map, cloud, association);
    RcsFitOptions view;
    view.incidence = IncidenceModel::kView;
    FitRcsModels(w->view_map, cloud, association, view);
    w->matching = std::make_unique<MatchingMap>(w->map);
    w->exact = std::make_unique<MatchingMap>(w->map, ExactMapOnly());
    return w;
  }();
  return *world;
}

constexpr int kTestScan = 40;

SE3d Perturbed(const SE3d& pose, double translation, double angle_deg, std::uint32_t seed) {
  std::mt19937 rng(seed);
  return SE3d(pose.rotation() * SO3d::Exp(angle_deg * M_PI / 180.0 * RandomUnitVector(rng)),
              pose.translation() + translation * RandomUnitVector(rng));
}

struct SolverCase {
  std::string name;
  double w_rcs;
};

std::unique_ptr<ScanMatcher> MakeSolver(const std::string& name, const ScanMatchingOptions& options) {
  return MakeScanMatcher(name, options);
}

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

INSTANTIATE_TEST_SUITE_P(
    EverySolver, SolverTest,
    ::testing::Values(SolverCase{"gn", 0.0}, SolverCase{"gn", 0.25}, SolverCase{"gn-autodiff", 0.0},
                      SolverCase{"gn-autodiff", 0.25}, SolverCase{"ceres", 0.0}, SolverCase{"ceres", 0.25},
                      SolverCase{"mh-gn", 0.0}, SolverCase{"mh-gn", 0.25}),
    [](const ::testing::TestParamInfo<SolverCase>& info) {
      std::string name = info.param.name + "_w" + std::to_string(int(info.param.w_rcs * 100));
      for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
      return name;
    });

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
    const double expected = EvaluateCost(c, result.pose, options);
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
    EXPECT_NEAR(f, EvaluateCost(c, pose, analytic), 1e-12 * f);
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
    ScanMatchingOptions curved = analytic;
    curved.loss_curvature = true;
    ScanMatchingOptions curved_autodiff = autodiff;
    curved_autodiff.loss_curvature = true;
    const LinearSystem gc = BuildGeometricSystem(c, pose, curved);
    const LinearSystem rc = BuildRcsSystem(c, pose, curved);
    EXPECT_GT(gc.loss_curvature.norm(), 1e-3 * gc.H.norm());  // Huber terms beyond a = 1
    EXPECT_GT(rc.loss_curvature.norm(), 1e-3 * rc.H.norm());  // Cauchy
    EXPECT_LT(Relative(gc.loss_curvature, BuildGeometricSystem(c, pose, curved_autodiff).loss_curvature), 1e-8);
    EXPECT_LT(Relative(rc.loss_curvature, BuildRcsSystem(c, pose, curved_autodiff).loss_curvature), 1e-8);
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
  options.loss_curvature = true;
  const Correspondences all =
      FindCorrespondences(world.simulated.scans[kTestScan], map, map.levels() - 1, pose, 3.0, true);
  int geometric_checked = 0, rcs_checked = 0;
  for (std::size_t k = 0; k < std::min<std::size_t>(all.geometric.size(), 40); ++k) {
    Correspondences one = all;
    one.geometric = {all.geometric[k]};
    const LinearSystem system = BuildGeometricSystem(one, pose, options);
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
    const LinearSystem system = BuildRcsSystem(one, pose, options);
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

// The paper's incidence direction, written out (the reference the library's
// IncidenceVector and FacingSign are tested against): d = normalize(u),
// u = p_r - mu_r (offset) or -mu_r (view), flipped when d.x > 0.
Eigen::Vector3d PaperIncidenceDirection(IncidenceModel incidence, const Eigen::Vector3d& point_radar,
                                        const Eigen::Vector3d& mean_radar) {
  Eigen::Vector3d d = incidence == IncidenceModel::kOffset ? Eigen::Vector3d(point_radar - mean_radar)
                                                           : Eigen::Vector3d(-mean_radar);
  d.normalize();
  if (d.x() > 0.0) d = -d;
  return d;
}

// The paper's RCS residual, with the direction re-evaluated at `pose`.
double PaperRcsResidual(const RcsTerm& term, const SE3d& pose) {
  const Eigen::Vector3d mean_radar = pose.rotation().Inverse() * (term.mean - pose.translation());
  const Eigen::Vector3d d = PaperIncidenceDirection(term.incidence, term.point_radar, mean_radar);
  return term.measurement - EvaluateSh<double>(term.degree, term.coefficients.data(), d);
}

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
    ScanMatchingOptions curved = options;
    curved.loss_curvature = true;
    const ScanMatchingResult gn_curved =
        GaussNewtonSolver(curved).Match(world.simulated.scans[kTestScan], single, initial);
    double dt = 0.0, dr = 0.0;
    PoseErrors(lm_unshared.pose, lm.pose, dt, dr);
    ASSERT_TRUE(lm_unshared.converged) << lm_unshared.reason;
    EXPECT_LT(dt, 1e-4) << "w " << w << ", a block per term";
    EXPECT_LT(dr * M_PI / 180.0, 1e-4) << "w " << w << ", a block per term";
    PoseErrors(lm_rows.pose, lm.pose, dt, dr);
    ASSERT_TRUE(lm_rows.converged) << lm_rows.reason;
    EXPECT_LT(dt, 1e-4) << "w " << w << ", shared rows";
    EXPECT_LT(dr * M_PI / 180.0, 1e-4) << "w " << w << ", shared rows";
    PoseErrors(dl.pose, lm.pose, dt, dr);
    ASSERT_TRUE(dl.converged) << dl.reason;
    EXPECT_LT(dt, 1e-4) << "w " << w << ", dogleg";
    EXPECT_LT(dr * M_PI / 180.0, 1e-4) << "w " << w << ", dogleg";
    PoseErrors(gn_curved.pose, lm.pose, dt, dr);
    ASSERT_TRUE(gn_curved.converged) << gn_curved.reason;
    EXPECT_LT(dt, 1e-4) << "w " << w << ", loss curvature";
    EXPECT_LT(dr * M_PI / 180.0, 1e-4) << "w " << w << ", loss curvature";
    PoseErrors(gn.pose, lm.pose, dt, dr);
    std::printf("w %.2f, %s incidence: GN cost %.10f (%d it), LM cost %.10f; pose difference %.2e m, %.2e rad\n",
                w, ToString(map->incidence).c_str(), gn.final_cost, gn.iterations, lm.final_cost, dt,
                dr * M_PI / 180.0);
    ASSERT_TRUE(gn.converged) << gn.reason;
    EXPECT_LT(dt, 1e-4) << "w " << w;
    EXPECT_LT(dr * M_PI / 180.0, 1e-4) << "w " << w;
    EXPECT_NEAR(gn.final_cost, lm.final_cost, 1e-6 + 1e-4 * gn.final_cost);
  }
}

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

// A Jacobian Ceres returned (compressed rows) as a dense matrix.
Eigen::MatrixXd Dense(const ceres::CRSMatrix& jacobian) {
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(jacobian.num_rows, jacobian.num_cols);
  for (int row = 0; row < jacobian.num_rows; ++row) {
    for (int k = jacobian.rows[row]; k < jacobian.rows[row + 1]; ++k) dense(row, jacobian.cols[k]) = jacobian.values[k];
  }
  return dense;
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
  struct Layout {
    JacobianMode jacobians;
    CeresBlocks blocks;  // asked for; autodiff terms always take a block each
    int threads;
    const char* name;
  };
  const Layout layouts[] = {{JacobianMode::kAutoDiff, CeresBlocks::kSquareRoot, 1, "autodiff"},
                            {JacobianMode::kAnalytic, CeresBlocks::kShared, 1, "analytic, shared rows"},
                            {JacobianMode::kAnalytic, CeresBlocks::kPerTerm, 1, "analytic, a block per term"},
                            {JacobianMode::kAnalytic, CeresBlocks::kSquareRoot, 1, "analytic, square root"},
                            {JacobianMode::kAnalytic, CeresBlocks::kSquareRoot, 3, "analytic, square root, 3 threads"}};
  constexpr int kLayouts = int(std::size(layouts));
  // Per layout: blocks and residuals of n terms with `rows` residuals each on a tangent space of `tangent`.
  const auto blocks_of = [](const Layout& layout, std::size_t n) -> std::size_t {
    if (layout.jacobians == JacobianMode::kAutoDiff || layout.blocks == CeresBlocks::kPerTerm) return n;
    if (layout.blocks == CeresBlocks::kShared) {
      return (n + CeresScanProblem::kTermsPerBlock - 1) / CeresScanProblem::kTermsPerBlock;
    }
    return std::min<std::size_t>(n, std::size_t(layout.threads));
  };
  const auto residuals_of = [&](const Layout& layout, std::size_t n, int rows, int tangent) -> std::size_t {
    const bool square_root = layout.jacobians == JacobianMode::kAnalytic && layout.blocks == CeresBlocks::kSquareRoot;
    return square_root ? blocks_of(layout, n) * (tangent + 1) : n * rows;
  };
  for (const bool trivial : {false, true}) {
    for (const RcsTranslation mode : {RcsTranslation::kRotationOnly, RcsTranslation::kFull}) {
      std::vector<double> gradients[kLayouts];  // per layout, all updates in a row
      std::vector<Eigen::Matrix<double, 6, 6>> shared_normal;  // J^T J of the shared rows, per update
      for (int l = 0; l < kLayouts; ++l) {
        const Layout& layout = layouts[l];
        ScanMatchingOptions options;
        options.jacobians = layout.jacobians;
        options.rcs_translation = mode;
        options.geometric_loss = trivial ? LossConfig{LossType::kTrivial, 1.0} : LossConfig{LossType::kHuber, 0.5};
        if (trivial) options.rcs_loss = {LossType::kTrivial, 1.0};
        const bool analytic = layout.jacobians == JacobianMode::kAnalytic;
        const bool shared_rows = analytic && layout.blocks == CeresBlocks::kShared;
        const bool square_root = analytic && layout.blocks == CeresBlocks::kSquareRoot;
        const SE3d pose = Perturbed(truth, 0.1, 0.5, 3);
        Eigen::Vector4d rotation = pose.rotation().quaternion().coeffs();
        Eigen::Vector3d translation = pose.translation();
        CeresScanProblem problem(options, rotation.data(), translation.data(), layout.blocks, layout.threads);
        struct Update {
          const RadarScan* scan;
          std::size_t level;
          double w;
        };
        int u = 0;
        for (const Update& update :
             {Update{&full_scan, map.levels() - 1, 0.25}, Update{&half_scan, 0, 0.0},
              Update{&full_scan, map.levels() - 1, 0.0}, Update{&half_scan, map.levels() - 1, 0.5},
              Update{&full_scan, map.levels() - 1, 1.0}, Update{&full_scan, map.levels() - 1, 0.25}}) {
          const Correspondences c = FindCorrespondences(*update.scan, map, update.level, pose, 3.0, update.w > 0.0);
          ASSERT_GT(c.geometric.size(), 2 * CeresScanProblem::kTermsPerBlock);
          if (update.w > 0.0) {
            ASSERT_GT(c.rcs.size(), CeresScanProblem::kTermsPerBlock);
          }
          problem.Update(c, update.w);
          ScanMatchingOptions weighted = options;
          weighted.w_rcs = update.w;
          const std::size_t n_geo = update.w < 1.0 ? c.geometric.size() : 0;
          const std::size_t n_rcs = update.w > 0.0 ? c.rcs.size() : 0;
          const int rcs_tangent = mode == RcsTranslation::kRotationOnly ? 3 : 6;
          EXPECT_EQ(problem.problem().NumResidualBlocks(), int(blocks_of(layout, n_geo) + blocks_of(layout, n_rcs)))
              << "w " << update.w << ", " << layout.name;
          EXPECT_EQ(problem.problem().NumResiduals(),
                    int(residuals_of(layout, n_geo, 3, 6) + residuals_of(layout, n_rcs, 1, rcs_tangent)))
              << "w " << update.w << ", " << layout.name;
          double cost = 0.0;
          std::vector<double> gradient;
          ceres::CRSMatrix jacobian;
          ASSERT_TRUE(problem.problem().Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, &gradient,
                                                 analytic ? &jacobian : nullptr));
          const double f = EvaluateCost(c, pose, weighted);
          EXPECT_NEAR(2.0 * cost, f, 1e-12 * f) << "w " << update.w << " level " << update.level << ", " << layout.name;
          // With residuals only (a candidate step's cost), the same cost.
          double cost_only = 0.0;
          ASSERT_TRUE(problem.problem().Evaluate(ceres::Problem::EvaluateOptions(), &cost_only, nullptr, nullptr,
                                                 nullptr));
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
          if (!shared_rows) continue;
          // Central differences of the residuals along the tangent coordinates
          // x = [dphi; dt] (Ceres's Jacobian columns: rotation, then translation).
          const Eigen::Vector4d rotation0 = rotation;
          const Eigen::Vector3d translation0 = translation;
          const Eigen::MatrixXd numeric = NumericJacobian(
              [&](const Eigen::VectorXd& x) {
                SO3Manifold().Plus(rotation0.data(), x.data(), rotation.data());
                translation = translation0 + x.tail<3>();
                std::vector<double> values;
                EXPECT_TRUE(
                    problem.problem().Evaluate(ceres::Problem::EvaluateOptions(), nullptr, &values, nullptr, nullptr));
                return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(values.data(), Eigen::Index(values.size())));
              },
              Eigen::VectorXd::Zero(6));
          rotation = rotation0;
          translation = translation0;
          ASSERT_EQ(jacobian.num_rows, numeric.rows());
          double worst = 0.0;  // entry by entry
          for (int row = 0; row < jacobian.num_rows; ++row) {
            const Eigen::Matrix<double, 1, 6> difference = dense.row(row) - numeric.row(row);
            const Eigen::Matrix<double, 1, 6> scale = dense.row(row).cwiseAbs() + numeric.row(row).cwiseAbs();
            worst = std::max(worst, (difference.cwiseAbs().array() / (1e-6 + scale.array())).maxCoeff());
          }
          EXPECT_LT(worst, 1e-5) << "w " << update.w << (trivial ? ", trivial losses" : ", robust losses");
        }
      }
      for (int l = 1; l < kLayouts; ++l) {
        ASSERT_EQ(gradients[l].size(), gradients[0].size());
        for (std::size_t i = 0; i < gradients[0].size(); ++i) {
          EXPECT_NEAR(gradients[l][i], gradients[0][i], 1e-8 * (1.0 + std::abs(gradients[0][i])))
              << "gradient entry " << i << ", " << layouts[l].name
              << (trivial ? ", trivial losses" : ", robust losses");
        }
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
    CeresScanProblem problem(ScanMatchingOptions(), rotation.data(), translation.data(), blocks);
    problem.Update(c, 0.5);
    Evaluation e;
    ceres::CRSMatrix jacobian;
    EXPECT_TRUE(problem.problem().Evaluate(ceres::Problem::EvaluateOptions(), &e.cost, nullptr, &e.gradient,
                                           &jacobian));
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

// A pure rotation error reduced by the RCS term alone, on planted
// parameters: Gaussians 6 to 12 m around the radar whose RCS models are
// planted degree-2 SH patterns, and a scan whose RCS values are those
// patterns evaluated at the true pose with the incidence law of DESIGN.md
// section 4, written out here independently of the residual code. With
// w = 1 and rotation-only the geometric term has no weight, so whatever
// corrects the rotation is the RCS term.
struct PlantedRcsWorld {
  GaussianMap map;
  RadarScan scan;
  SE3d truth;
};

PlantedRcsWorld MakePlantedRcsWorld(IncidenceModel incidence, double rcs_noise) {
  PlantedRcsWorld world;
  world.map.incidence = incidence;
  world.truth = SE3d(SO3d::Exp(Eigen::Vector3d(0.05, -0.03, 0.4)), Eigen::Vector3d(3.0, -1.0, 0.5));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coefficient(-0.35, 0.35), offset(-0.12, 0.12);
  std::normal_distribution<double> noise(0.0, rcs_noise);
  world.scan.has_rcs = true;
  for (int azimuth = -60; azimuth <= 60; azimuth += 10) {
    for (const int elevation : {-8, 0, 8}) {
      const double range = 6.0 + 3.0 * ((azimuth / 10 + elevation / 8 + 9) % 3);
      const double a = azimuth * M_PI / 180.0, e = elevation * M_PI / 180.0;
      const Eigen::Vector3d mean_radar = range * Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
      Gaussian g;
      g.mean = world.truth * mean_radar;
      g.covariance = 0.15 * 0.15 * Eigen::Matrix3d::Identity();
      g.rcs.degree = 2;
      g.rcs.median = 0.0;
      g.rcs.scale = 1.0;
      for (int i = 1; i < ShCoefficientCount(2); ++i) g.rcs.coefficients[i] = coefficient(rng);
      for (int k = 0; k < 12; ++k) {
        RadarPoint point;
        point.position = world.truth.Inverse() * (g.mean + Eigen::Vector3d(offset(rng), offset(rng), offset(rng)));
        // d in the radar frame at the true pose.
        const Eigen::Vector3d d = PaperIncidenceDirection(incidence, point.position, mean_radar);
        const Eigen::Matrix<double, 9, 1> basis = ShBasis<2, double>(d);
        point.rcs = basis.dot(Eigen::Map<const Eigen::Matrix<double, 9, 1>>(g.rcs.coefficients.data())) + noise(rng);
        world.scan.points.push_back(point);
      }
      world.map.gaussians.push_back(g);
    }
  }
  return world;
}

TEST(RotationOnlyRcs, RcsAloneReducesAPureRotationErrorOnPlantedModels) {
  // Exact patterns: both incidence models recover the truth. With RCS noise
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
        EXPECT_LT(dr, rcs_noise == 0.0 ? 1e-6 : 0.1) << name << ", " << ToString(incidence) << " incidence";
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

// Lazy re-association on the exact map: the solver keeps the association
// while the pose stays within the thresholds of where it was made. With the
// thresholds at 0 it re-associates after every step (the textbook loop);
// both end at the same optimum to well within the association's own
// resolution, the lazy one with fewer associations (fewer iterations here,
// as small steps no longer make points swap Gaussians back and forth).
TEST(LazyReassociation, SameOptimumFewerIterations) {
  const World& world = SimulatedWorld();
  const MatchingMap& exact = *world.exact;
  double eager_iterations = 0.0, lazy_iterations = 0.0;
  for (const int scan : {20, 40, 60}) {
    const SE3d truth = world.simulated.ground_truth[scan].pose;
    const SE3d initial = Perturbed(truth, 0.05, 0.2, std::uint32_t(scan));
    ScanMatchingOptions eager;
    eager.reassociation_translation = eager.reassociation_rotation = 0.0;
    const ScanMatchingOptions lazy;
    const ScanMatchingResult a = GaussNewtonSolver(eager).Match(world.simulated.scans[scan], exact, initial);
    const ScanMatchingResult b = GaussNewtonSolver(lazy).Match(world.simulated.scans[scan], exact, initial);
    double dt = 0.0, dr = 0.0;
    PoseErrors(a.pose, b.pose, dt, dr);
    EXPECT_LT(dt, 0.02) << "scan " << scan;
    EXPECT_LT(dr, 0.1) << "scan " << scan;
    EXPECT_TRUE(b.converged) << b.reason;
    eager_iterations += a.iterations;
    lazy_iterations += b.iterations;
  }
  std::printf("iterations over 3 scans: eager %.0f, lazy %.0f\n", eager_iterations, lazy_iterations);
  EXPECT_LT(lazy_iterations, eager_iterations);
}

// coarse_points subsamples the coarse levels only: a limit above the scan
// size changes nothing, a small one changes the path.
TEST(CoarsePoints, SubsamplesCoarseLevelsOnly) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const SE3d initial = Perturbed(world.simulated.ground_truth[kTestScan].pose, 2.0, 5.0, 1);
  ScanMatchingOptions all, above, few;
  above.coarse_points = scan.points.size() + 1;
  few.coarse_points = 20;
  const SE3d a = GaussNewtonSolver(all).Match(scan, *world.matching, initial).pose;
  const SE3d b = GaussNewtonSolver(above).Match(scan, *world.matching, initial).pose;
  const SE3d c = GaussNewtonSolver(few).Match(scan, *world.matching, initial).pose;
  EXPECT_EQ(a.translation(), b.translation());
  EXPECT_NE(a.translation(), c.translation());
}

// The coarse levels stop on their own tolerances, the exact map on its own:
// coarse tolerances so large that every first step is small end each coarse
// level after one iteration (the exact map's iterations unchanged in kind),
// and invalid ones are rejected.
TEST(CoarseTolerances, EndCoarseLevelsOnly) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const SE3d initial = Perturbed(world.simulated.ground_truth[kTestScan].pose, 2.0, 5.0, 1);
  ScanMatchingOptions loose;
  loose.coarse_translation_tolerance = 1e3;
  loose.coarse_rotation_tolerance = 1e3;
  const ScanMatchingResult defaults = GaussNewtonSolver(ScanMatchingOptions{}).Match(scan, *world.matching, initial);
  ScanMatchingOptions exact_only = loose;
  exact_only.max_iterations = 1;  // one iteration on the exact map: the coarse levels' count is what remains
  const ScanMatchingResult one = GaussNewtonSolver(exact_only).Match(scan, *world.matching, initial);
  EXPECT_EQ(one.iterations, int(world.matching->levels()));
  EXPECT_GT(defaults.iterations, int(world.matching->levels()) + 1);
  ScanMatchingOptions bad;
  bad.coarse_translation_tolerance = 0.0;
  EXPECT_THROW(GaussNewtonSolver{bad}, std::invalid_argument);
  bad = ScanMatchingOptions{};
  bad.coarse_rotation_tolerance = -1.0;
  EXPECT_THROW(CeresSolver{bad}, std::invalid_argument);
}

// AddRcsTerms gives the RCS terms FindCorrespondences makes with_rcs, from
// the geometric pairs alone; each pair names the scan point it came from.
TEST(Correspondences, AddRcsTermsAsAssociatingWithRcs) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const MatchingMap& exact = *world.exact;
  const SE3d pose = Perturbed(world.simulated.ground_truth[kTestScan].pose, 0.1, 0.5, 3);
  const Correspondences with_rcs = FindCorrespondences(scan, exact, 0, pose, 3.0, true);
  Correspondences added = FindCorrespondences(scan, exact, 0, pose, 3.0, false);
  EXPECT_TRUE(added.rcs.empty());
  for (const GeometricTerm& pair : added.geometric) {
    ASSERT_LT(pair.point, scan.points.size());
    EXPECT_EQ(scan.points[pair.point].position, pair.point_radar);
  }
  AddRcsTerms(scan, exact, added);
  ASSERT_GT(with_rcs.rcs.size(), 100u);
  ASSERT_EQ(added.rcs.size(), with_rcs.rcs.size());
  for (std::size_t k = 0; k < added.rcs.size(); ++k) {
    const RcsTerm &a = added.rcs[k], &b = with_rcs.rcs[k];
    EXPECT_EQ(a.gaussian, b.gaussian) << k;
    EXPECT_EQ(a.point_radar, b.point_radar) << k;
    EXPECT_EQ(a.measurement, b.measurement) << k;
    EXPECT_EQ(a.facing, b.facing) << k;
    EXPECT_EQ(a.coefficients, b.coefficients) << k;
  }
  ScanMatchingOptions options;
  options.w_rcs = 0.25;
  EXPECT_EQ(EvaluateCost(added, pose, options), EvaluateCost(with_rcs, pose, options));
  AddRcsTerms(scan, exact, added);  // replaces, does not append
  EXPECT_EQ(added.rcs.size(), with_rcs.rcs.size());
  RadarScan no_rcs = scan;
  no_rcs.has_rcs = false;
  AddRcsTerms(no_rcs, exact, added);
  EXPECT_TRUE(added.rcs.empty());
}

// geometric_first: with 0 < w < 1 the exact map is matched with the
// geometric term alone (coarse tolerances), then with eq. 2 on that stage's
// last association while the pose stays within its re-association
// thresholds (a new association otherwise). Without it, without
// re-association, and with w = 0 or 1: eq. 2 alone on the exact map.
TEST(GeometricFirst, ExactMapGeometricStageThenEq2) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const MatchingMap& matching = *world.matching;
  const std::size_t coarse = matching.levels() - 1;
  const SE3d initial = Perturbed(world.simulated.ground_truth[kTestScan].pose, 0.1, 0.5, 5);
  struct Stage {
    bool finest;
    double w, translation_tolerance;
    Correspondences c;
  };
  // One step per stage; `move` shifts the pose by that much (x) in the
  // exact map's geometric stage.
  const auto stages = [&](const ScanMatchingOptions& options, double move) {
    std::vector<Stage> seen;
    RunCoarseToFine(scan, matching, initial, options, [&](const LevelStep& step, ScanMatchingResult& result) {
      seen.push_back({step.finest, step.options.w_rcs, step.translation_tolerance, step.correspondences});
      if (step.finest && step.options.w_rcs == 0.0 && move > 0.0) {
        result.pose = SE3d(result.pose.rotation(), result.pose.translation() + Eigen::Vector3d(move, 0, 0));
      }
      return StepOutcome::kConverged;
    });
    return seen;
  };
  ScanMatchingOptions options;
  options.w_rcs = 0.25;
  std::vector<Stage> seen = stages(options, 0.0);
  ASSERT_EQ(seen.size(), coarse + 2);
  for (std::size_t k = 0; k < coarse; ++k) EXPECT_FALSE(seen[k].finest);
  const Stage &geometric = seen[coarse], &full = seen[coarse + 1];
  EXPECT_TRUE(geometric.finest && full.finest);
  EXPECT_EQ(geometric.w, 0.0);
  EXPECT_TRUE(geometric.c.rcs.empty());
  EXPECT_EQ(geometric.translation_tolerance, options.coarse_translation_tolerance);
  EXPECT_EQ(full.w, 0.25);
  EXPECT_EQ(full.translation_tolerance, options.translation_tolerance);
  // The same association, now with its RCS terms.
  EXPECT_TRUE(SamePose(full.c.pose, geometric.c.pose));
  ASSERT_EQ(full.c.geometric.size(), geometric.c.geometric.size());
  for (std::size_t k = 0; k < full.c.geometric.size(); ++k) {
    EXPECT_EQ(full.c.geometric[k].gaussian, geometric.c.geometric[k].gaussian) << k;
  }
  EXPECT_EQ(full.c.rcs.size(), FindCorrespondences(scan, matching, coarse, full.c.pose, options.gate, true).rcs.size());
  EXPECT_GT(full.c.rcs.size(), 0u);
  // A geometric stage that moves the pose within the thresholds: its association is kept.
  seen = stages(options, 0.5 * options.reassociation_translation);
  ASSERT_EQ(seen.size(), coarse + 2);
  EXPECT_TRUE(SamePose(seen[coarse + 1].c.pose, seen[coarse].c.pose));
  // A geometric stage that moves the pose past the thresholds: eq. 2 associates anew there.
  seen = stages(options, 2.0 * options.reassociation_translation);
  ASSERT_EQ(seen.size(), coarse + 2);
  const double moved = (seen[coarse + 1].c.pose.translation() - seen[coarse].c.pose.translation()).x();
  EXPECT_NEAR(moved, 2.0 * options.reassociation_translation, 1e-12);
  EXPECT_GT(seen[coarse + 1].c.rcs.size(), 0u);
  // Eq. 2 alone on the exact map.
  ScanMatchingOptions off = options;
  off.geometric_first = false;
  ScanMatchingOptions once = options;
  once.reassociate = false;
  ScanMatchingOptions zero = options;
  zero.w_rcs = 0.0;
  for (const ScanMatchingOptions& o : {off, once, zero}) {
    seen = stages(o, 0.0);
    ASSERT_EQ(seen.size(), coarse + 1);
    EXPECT_EQ(seen.back().w, o.w_rcs);
    EXPECT_EQ(seen.back().translation_tolerance, o.translation_tolerance);
  }
  ScanMatchingOptions one = options;
  one.w_rcs = 1.0;
  seen = stages(one, 0.0);
  ASSERT_EQ(seen.size(), 1u);  // no coarse levels, no geometric stage
  EXPECT_EQ(seen[0].w, 1.0);
}

// The same optimum with and without geometric_first (to the association's
// resolution), within 5 cm / 0.2 deg of the truth, from the paper's initial
// errors (coarse levels) and from a tracking error (exact map alone), for
// the own GN and Ceres LM at w = 0.25.
TEST(GeometricFirst, SameOptimumAsEq2Throughout) {
  const World& world = SimulatedWorld();
  for (const int scan : {kTestScan, 60}) {
    const SE3d truth = world.simulated.ground_truth[scan].pose;
    for (const bool far : {true, false}) {
      const SE3d initial = far ? Perturbed(truth, 2.0, 5.0, std::uint32_t(scan)) : Perturbed(truth, 0.05, 0.2, 7);
      const MatchingMap& map = far ? *world.matching : *world.exact;
      for (const std::string solver : {"gn", "ceres"}) {
        ScanMatchingOptions first;
        first.w_rcs = 0.25;
        ScanMatchingOptions throughout = first;
        throughout.geometric_first = false;
        const ScanMatchingResult a = MakeScanMatcher(solver, first)->Match(world.simulated.scans[scan], map, initial);
        const ScanMatchingResult b =
            MakeScanMatcher(solver, throughout)->Match(world.simulated.scans[scan], map, initial);
        const std::string where = solver + ", scan " + std::to_string(scan) + (far ? ", 2 m / 5 deg" : ", tracking");
        ASSERT_TRUE(a.converged) << a.reason << " " << where;
        ASSERT_TRUE(b.converged) << b.reason << " " << where;
        double dt = 0.0, dr = 0.0;
        PoseErrors(a.pose, b.pose, dt, dr);
        std::printf("%s: %.4f m / %.4f deg apart, iterations %d / %d\n", where.c_str(), dt, dr, a.iterations,
                    b.iterations);
        EXPECT_LT(dt, 0.02) << where;  // the association's resolution, as LazyReassociation
        EXPECT_LT(dr, 0.1) << where;
        PoseErrors(a.pose, truth, dt, dr);
        EXPECT_LT(dt, 0.05) << where;
        EXPECT_LT(dr, 0.2) << where;
        EXPECT_GT(a.n_rcs, 0u) << where;
      }
    }
  }
}

// Merged coarse levels: the Gaussians whose means share a voxel of side
// kMergeCellPerSigma * sigma become their moment-matched mixture (weights:
// member counts), blurred by sigma^2 I. Reference by hand: two Gaussians
// a = 2 m apart along x with weights 1 and 3 merge to the weighted mean and
// Sigma_mix = sum w_i Sigma_i / W + (w1 w2 / W^2) a^2 e_x e_x^T.
TEST(MergedCoarseLevels, MomentMatchedMixturePerVoxel) {
  GaussianMap map;
  Gaussian first, second, far;
  first.mean = Eigen::Vector3d(0.2, 0.5, 0.5);
  first.covariance = Eigen::Vector3d(0.04, 0.09, 0.01).asDiagonal();
  first.point_count = 1;
  second.mean = Eigen::Vector3d(2.2, 0.5, 0.5);
  second.covariance = 0.01 * Eigen::Matrix3d::Identity();
  second.point_count = 3;
  far.mean = Eigen::Vector3d(20.0, 0.5, 0.5);
  far.covariance = 0.01 * Eigen::Matrix3d::Identity();
  far.point_count = 2;
  map.gaussians = {first, second, far};
  MatchingMapOptions options;
  options.inflation = {1.0};
  options.coarse = CoarseLevels::kMerged;
  const MatchingMap matching(map, options);
  ASSERT_EQ(matching.levels(), 2u);
  const GaussianIndex& coarse = matching.level(0);
  ASSERT_EQ(coarse.size(), 2u);  // {first, second} and {far}
  const std::size_t merged = coarse.Mean(0).x() < 10.0 ? 0 : 1;
  const Eigen::Vector3d expected_mean(0.25 * 0.2 + 0.75 * 2.2, 0.5, 0.5);
  Eigen::Matrix3d expected_covariance = 0.25 * first.covariance + 0.75 * second.covariance;
  expected_covariance(0, 0) += 0.25 * 0.75 * 2.0 * 2.0;
  expected_covariance += Eigen::Matrix3d::Identity();  // sigma = 1
  EXPECT_LT((coarse.Mean(merged) - expected_mean).norm(), 1e-12);
  EXPECT_LT((coarse.Information(merged).inverse() - expected_covariance).norm(), 1e-9);
  const Eigen::Matrix3d far_covariance = far.covariance + Eigen::Matrix3d::Identity();
  EXPECT_LT((coarse.Mean(1 - merged) - far.mean).norm(), 1e-12);
  EXPECT_LT((coarse.Information(1 - merged).inverse() - far_covariance).norm(), 1e-9);
  // The exact level is the map itself.
  EXPECT_EQ(matching.index().size(), 3u);
  // Index cells: half the merge cell on a merged level, sigma on an inflated
  // one, at least index_cell.
  EXPECT_EQ(coarse.cell_size(), 1.5);
  EXPECT_EQ(matching.index().cell_size(), options.index_cell);
  options.coarse = CoarseLevels::kInflated;
  options.inflation = {1.0, 0.25};
  const MatchingMap inflated(map, options);
  EXPECT_EQ(inflated.level(0).cell_size(), 1.0);
  EXPECT_EQ(inflated.level(1).cell_size(), options.index_cell);
  EXPECT_THROW(CoarseLevelsFromString("blurred"), std::invalid_argument);
  EXPECT_EQ(CoarseLevelsFromString(ToString(CoarseLevels::kMerged)), CoarseLevels::kMerged);
}

// With merged coarse levels (matching the scan's voxel centroids or 400 of
// its points there, and with a coarse gate of 2) the solvers still reach
// 5 cm / 0.2 deg on the test scan from 2 m / 5 deg.
TEST(MergedCoarseLevels, ConvergesFromTwoMetresFiveDegrees) {
  const World& world = SimulatedWorld();
  const RadarScan& scan = world.simulated.scans[kTestScan];
  const SE3d truth = world.simulated.ground_truth[kTestScan].pose;
  for (const double coarse_gate : {3.0, 2.0}) {
    MatchingMapOptions merged_options;
    merged_options.coarse = CoarseLevels::kMerged;
    merged_options.coarse_gate = coarse_gate;
    const MatchingMap merged(world.map, merged_options);
    ASSERT_LT(merged.level(0).size(), world.matching->level(0).size() / 4);
    for (const std::string name : {"gn", "ceres"}) {
      for (const double w : {0.0, 0.25}) {
        for (const std::size_t coarse_points : {std::size_t(0), std::size_t(400)}) {
          ScanMatchingOptions options;
          options.w_rcs = w;
          options.coarse_points = coarse_points;
          options.coarse_voxel_per_sigma = coarse_points > 0 ? 0.0 : 2.0;  // the points, or voxel centroids
          const auto solver = MakeSolver(name, options);
          for (const std::uint32_t seed : {1u, 2u, 3u}) {
            const ScanMatchingResult result = solver->Match(scan, merged, Perturbed(truth, 2.0, 5.0, seed));
            double dt = 0.0, dr = 0.0;
            PoseErrors(result.pose, truth, dt, dr);
            const std::string where = name + " w " + std::to_string(w) + " coarse points " +
                                      std::to_string(coarse_points) + " coarse gate " +
                                      std::to_string(coarse_gate) + " seed " + std::to_string(seed);
            EXPECT_TRUE(result.converged) << result.reason << " " << where;
            EXPECT_LT(dt, 0.05) << where;
            EXPECT_LT(dr, 0.2) << where;
          }
        }
      }
    }
  }
}

// The hand-built map of the coarse-level tests: one Gaussian at the origin,
// Sigma = 0.01 I (0.1 m std).
GaussianMap OneGaussianAtTheOrigin() {
  GaussianMap map;
  Gaussian g;
  g.covariance = 0.01 * Eigen::Matrix3d::Identity();
  g.point_count = 10;
  map.gaussians = {g};
  return map;
}

// A scan of points at `positions` (no RCS, no Doppler).
RadarScan ScanOf(const std::vector<Eigen::Vector3d>& positions) {
  RadarScan scan;
  for (const Eigen::Vector3d& p : positions) {
    RadarPoint point;
    point.position = p;
    scan.points.push_back(point);
  }
  return scan;
}

// The coarse gate: on a coarse level a point goes to a blurred Gaussian only
// within coarse_gate (the exact map keeps ScanMatchingOptions::gate), and the
// level's index lists a Gaussian only in the cells of its +/- coarse_gate box.
// One Gaussian at the origin, Sigma = 0.01 I, blurred by sigma = 1 m:
// Sigma_1 = 1.01 I, so a point at radius r is r / 1.005 blurred std away.
TEST(CoarseGate, CoarseLevelsAssociateWithinIt) {
  const GaussianMap map = OneGaussianAtTheOrigin();
  const RadarScan scan = ScanOf({Eigen::Vector3d(1.5, 0, 0), Eigen::Vector3d(0, 1.5, 0), Eigen::Vector3d(0, 0, -1.5),
                                 Eigen::Vector3d(2.6, 0, 0), Eigen::Vector3d(0, -2.6, 0), Eigen::Vector3d(0, 0, 2.6)});
  ScanMatchingOptions options;  // gate 3 on the exact map
  options.coarse_voxel_per_sigma = 0.0;  // the points themselves
  for (const double coarse_gate : {3.0, 2.0}) {
    MatchingMapOptions map_options;
    map_options.inflation = {1.0};
    map_options.coarse_gate = coarse_gate;
    const MatchingMap matching(map, map_options);
    EXPECT_EQ(matching.coarse_gate(), coarse_gate);
    std::vector<std::size_t> associated;  // per level visited
    const auto record = [&](const LevelStep& step, ScanMatchingResult&) {
      associated.push_back(step.correspondences.geometric.size());
      return StepOutcome::kConverged;
    };
    const ScanMatchingResult result = RunCoarseToFine(scan, matching, SE3d(), options, record);
    // The coarse level: the 1.5 m points (1.49 std) always, the 2.6 m ones
    // (2.59 std) only within a gate of 3. The exact map (0.1 m std): none.
    ASSERT_EQ(associated.size(), 1u);
    EXPECT_EQ(associated[0], coarse_gate > 2.59 ? 6u : 3u);
    EXPECT_FALSE(result.converged);
    EXPECT_EQ(result.reason, "no point associated to the map");
    // Cells of side 1 m: the cell of x = 3.2 m meets the ellipsoid of 3 std
    // (to 3.015 m), not that of 2 std (2.01 m).
    std::size_t count = 0;
    matching.level(0).Candidates(Eigen::Vector3d(3.2, 0.0, 0.0), count);
    EXPECT_EQ(count, coarse_gate == 3.0 ? 1u : 0u);
  }
  MatchingMapOptions bad;
  bad.coarse_gate = 0.0;
  EXPECT_THROW(MatchingMap(map, bad), std::invalid_argument);
}

// Coarse voxels: each coarse level matches the centroids of the scan's voxels
// of side coarse_voxel_per_sigma * sigma_k (then at most coarse_points of
// them, evenly strided). One Gaussian at the origin, levels blurred by 1 and
// 0.5 m, voxels of 2 and 1 m; the centroids by hand.
TEST(CoarseVoxels, CoarseLevelsMatchTheScansVoxelCentroids) {
  const GaussianMap map = OneGaussianAtTheOrigin();
  const Eigen::Vector3d a(0.2, 0.2, 0.2), b(0.6, 0.4, 0.2), c(1.4, 0.2, 0.2), d(-0.5, 0.3, 0.2);
  const RadarScan scan = ScanOf({a, b, c, d});
  MatchingMapOptions map_options;
  map_options.inflation = {1.0, 0.5};
  const MatchingMap matching(map, map_options);
  EXPECT_EQ(matching.sigma(0), 1.0);
  EXPECT_EQ(matching.sigma(1), 0.5);
  EXPECT_EQ(matching.sigma(2), 0.0);  // the exact map
  const auto coarse_points = [&](const ScanMatchingOptions& options) {
    std::vector<std::vector<Eigen::Vector3d>> levels;  // the associated points, per coarse level
    const auto record = [&](const LevelStep& step, ScanMatchingResult&) {
      if (!step.finest) {
        levels.emplace_back();
        for (const GeometricTerm& term : step.correspondences.geometric) levels.back().push_back(term.point_radar);
      }
      return StepOutcome::kConverged;
    };
    RunCoarseToFine(scan, matching, SE3d(), options, record);
    return levels;
  };
  const auto expect_points = [](const std::vector<Eigen::Vector3d>& got, const std::vector<Eigen::Vector3d>& want,
                                const std::string& where) {
    ASSERT_EQ(got.size(), want.size()) << where;
    for (std::size_t k = 0; k < want.size(); ++k) EXPECT_LT((got[k] - want[k]).norm(), 1e-12) << where << " " << k;
  };
  ScanMatchingOptions options;
  options.coarse_voxel_per_sigma = 2.0;
  auto levels = coarse_points(options);
  ASSERT_EQ(levels.size(), 2u);
  expect_points(levels[0], {(a + b + c) / 3.0, d}, "2 m voxels");  // in the order of their first points
  expect_points(levels[1], {(a + b) / 2.0, c, d}, "1 m voxels");
  options.coarse_points = 2;  // of the centroids, evenly strided
  levels = coarse_points(options);
  ASSERT_EQ(levels.size(), 2u);
  expect_points(levels[0], {(a + b + c) / 3.0, d}, "2 m voxels, 2 points");
  expect_points(levels[1], {(a + b) / 2.0, c}, "1 m voxels, 2 points");
  ScanMatchingOptions points;
  points.coarse_voxel_per_sigma = 0.0;  // without voxels: the points themselves
  levels = coarse_points(points);
  ASSERT_EQ(levels.size(), 2u);
  expect_points(levels[0], {a, b, c, d}, "points");
  ScanMatchingOptions bad;
  bad.coarse_voxel_per_sigma = -1.0;
  EXPECT_THROW(GaussNewtonSolver{bad}, std::invalid_argument);
  bad.coarse_voxel_per_sigma = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(CeresSolver{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace radargauss

#include "radargauss/solvers/joint_refinement.hpp"

namespace radargauss {
namespace {

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
    std::printf("joint refinement (%s, %zu scans): pose error %.3f m / %.3f deg -> %.3f m / %.3f deg; "
                "RCS residual RMS %.4f -> %.4f; %d iterations, %.0f ms\n",
                schur ? "SPARSE_SCHUR" : "SPARSE_NORMAL_CHOLESKY", scans.size(), t0, r0, t1, r1, rms0, rms1,
                result.iterations, result.time_ms);
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
      largest_difference = std::max(largest_difference, std::abs(autodiff.map.gaussians[g].rcs.coefficients[i] - analytic));
    }
  }
  EXPECT_GT(largest_coefficient_change, 1e-3);  // the coefficients did move
  EXPECT_LT(largest_difference, 1e-6);
  EXPECT_THROW(RefineJointly(scans, {}, world.map, JointRefinementOptions{}), std::invalid_argument);
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
      EvaluateCost(FindCorrespondences(world.scan, single, 0, initial, options.gate, true), initial, options);
  double checked = initial_cost, plain_highest = 0.0;
  for (int k = 1; k <= 12; ++k) {
    options.max_iterations = k;
    options.max_step_halvings = 8;
    const ScanMatchingResult result = MakeSolver("gn", options)->Match(world.scan, single, initial);
    EXPECT_LE(result.final_cost, checked * (1.0 + 1e-12)) << k << " iterations";
    checked = result.final_cost;
    options.max_step_halvings = 0;
    plain_highest = std::max(plain_highest, MakeSolver("gn", options)->Match(world.scan, single, initial).final_cost);
  }
  EXPECT_LT(checked, 0.75 * initial_cost);
  EXPECT_GT(plain_highest, initial_cost);
}

}  // namespace
}  // namespace radargauss
