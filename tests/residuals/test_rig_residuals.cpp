// SPDX-License-Identifier: BSD-3-Clause
// The residuals of a rig's calibration: the Doppler with an extrinsic and a
// clock block, analytic against autodiff and central differences; zero
// where the Doppler is the rig's model (core/rig_twist.hpp), and its clock
// derivative against the model evaluated at a moved time.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include <Eigen/Cholesky>

#include "radargauss/core/rig_twist.hpp"
#include "radargauss/residuals/rig_doppler_residual.hpp"
#include "support/cost_function_checks.hpp"

namespace radargauss {
namespace {

using testing::RandomUnitVector;

TEST(ResidualJacobians, RigDopplerAnalyticAutodiffNumeric) {
  std::mt19937 rng(31);
  for (int trial = 0; trial < 20; ++trial) {
    ReferenceMotion motion;
    motion.velocity = 10.0 * RandomUnitVector(rng);
    motion.angular_velocity = 0.5 * RandomUnitVector(rng);
    motion.acceleration = 2.0 * RandomUnitVector(rng);
    motion.angular_acceleration = 0.3 * RandomUnitVector(rng);
    const SE3d mounting(SO3d::Exp(2.0 * RandomUnitVector(rng)), 3.0 * RandomUnitVector(rng));
    const Eigen::Vector3d point = 20.0 * RandomUnitVector(rng);
    // The rig's model at the stated motion: zero residual with no clock change.
    const double doppler = RigDoppler(point, mounting, motion.velocity, motion.angular_velocity);
    Eigen::Vector4d q = mounting.rotation().quaternion().coeffs();
    Eigen::Vector3d t = mounting.translation();
    double d = 0.0;
    const RigDopplerCostFunction analytic(point, doppler, motion, 20.0);
    const std::unique_ptr<ceres::CostFunction> autodiff(RigDopplerResidual::Create(point, doppler, motion, 20.0));
    std::vector<Eigen::MatrixXd> ja, jd;
    EXPECT_LT(EvaluateWithJacobians(analytic, {q.data(), t.data(), &d}, ja).norm(), 1e-9);
    q = (mounting.rotation() * SO3d::Exp(0.1 * RandomUnitVector(rng))).quaternion().coeffs();
    t += 0.2 * RandomUnitVector(rng);
    d = 0.02;
    const std::vector<double*> blocks = {q.data(), t.data(), &d};
    const Eigen::VectorXd ra = EvaluateWithJacobians(analytic, blocks, ja);
    const Eigen::VectorXd rd = EvaluateWithJacobians(*autodiff, blocks, jd);
    EXPECT_LT(std::abs(ra(0) - rd(0)), 1e-10);
    for (int b = 0; b < 3; ++b) {
      EXPECT_LT(Relative(ja[b], jd[b]), 1e-8) << "block " << b;
      EXPECT_LT(Relative(ja[b], NumericBlockJacobian(analytic, blocks, b)), 1e-5) << "block " << b;
    }
  }
}

TEST(ResidualJacobians, RigPointAnalyticAutodiffNumeric) {
  std::mt19937 rng(37);
  for (int trial = 0; trial < 20; ++trial) {
    ReferenceMotion motion;
    motion.velocity = 10.0 * RandomUnitVector(rng);
    motion.angular_velocity = 0.5 * RandomUnitVector(rng);
    Eigen::Vector4d q = SO3d::Exp(2.0 * RandomUnitVector(rng)).quaternion().coeffs();
    Eigen::Vector3d t = 3.0 * RandomUnitVector(rng);
    double d = 0.03;
    const Eigen::Vector3d p = 30.0 * RandomUnitVector(rng), mean = 30.0 * RandomUnitVector(rng);
    Eigen::Matrix3d A = Eigen::Matrix3d::Random();
    const Eigen::Matrix3d LT = (A * A.transpose() + Eigen::Matrix3d::Identity()).llt().matrixU();
    const RigPointCostFunction analytic(p, mean, LT, motion);
    const std::unique_ptr<ceres::CostFunction> autodiff(RigPointResidual::Create(p, mean, LT, motion));
    std::vector<Eigen::MatrixXd> ja, jd;
    const std::vector<double*> blocks = {q.data(), t.data(), &d};
    const Eigen::VectorXd ra = EvaluateWithJacobians(analytic, blocks, ja);
    const Eigen::VectorXd rd = EvaluateWithJacobians(*autodiff, blocks, jd);
    EXPECT_LT((ra - rd).norm(), 1e-10);
    for (int b = 0; b < 3; ++b) {
      EXPECT_LT(Relative(ja[b], jd[b]), 1e-8) << "block " << b;
      EXPECT_LT(Relative(ja[b], NumericBlockJacobian(analytic, blocks, b)), 1e-5) << "block " << b;
    }
  }
}

// Where the reference was d earlier, at a constant twist: the residual at d
// against the point moved by Exp(-xi d) is of second order in d (1 mm at
// 26 m and 0.4 rad/s over 20 ms, a hundredth of that over 2 ms).
TEST(ResidualJacobians, RigPointClockChangeMovesThePointWithTheReference) {
  ReferenceMotion motion;
  motion.velocity = Eigen::Vector3d(6.0, 0.3, 0.0);
  motion.angular_velocity = Eigen::Vector3d(0.0, 0.0, 0.4);
  const Eigen::Vector3d p(25.0, -8.0, 1.0);
  Eigen::Vector4d q = SO3d().quaternion().coeffs();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  for (const double d : {0.02, 0.002}) {
    Eigen::Matrix<double, 6, 1> xi;
    xi << motion.velocity, motion.angular_velocity;
    const Eigen::Vector3d exact = SE3d::Exp(-d * xi) * p;
    const RigPointCostFunction cost(p, exact, Eigen::Matrix3d::Identity(), motion);
    Eigen::Vector3d residual;
    double change = d;
    const double* blocks[] = {q.data(), t.data(), &change};
    ASSERT_TRUE(cost.Evaluate(blocks, residual.data(), nullptr));
    // The second-order term: d^2 / 2 |w x (w x p) + w x v|.
    const Eigen::Vector3d& w = motion.angular_velocity;
    EXPECT_LT(residual.norm(), 0.5 * d * d * (w.norm() * w.norm() * p.norm() + w.norm() * motion.velocity.norm())) << d;
    EXPECT_GT(residual.norm(), 0.1 * 0.5 * d * d * w.norm() * w.norm() * p.norm()) << d;  // second order, not zero
  }
}

// A clock offset larger by d reads the reference's motion d earlier: the
// residual at d against the model at v - a d, w - alpha d, by hand.
TEST(ResidualJacobians, RigDopplerClockChangeReadsTheMotionEarlier) {
  ReferenceMotion motion;
  motion.velocity = Eigen::Vector3d(8.0, 0.5, 0.0);
  motion.angular_velocity = Eigen::Vector3d(0.0, 0.0, 0.3);
  motion.acceleration = Eigen::Vector3d(1.5, -0.4, 0.0);
  motion.angular_acceleration = Eigen::Vector3d(0.0, 0.0, 0.2);
  const SE3d mounting(SO3d::Exp(Eigen::Vector3d(0.0, 0.0, 0.8)), Eigen::Vector3d(-0.9, 0.9, 0.6));
  const Eigen::Vector3d point(12.0, -3.0, 1.0);
  const double d = 0.015;
  const double earlier = RigDoppler(point, mounting, motion.velocity - d * motion.acceleration,
                                    motion.angular_velocity - d * motion.angular_acceleration);
  Eigen::Vector4d q = mounting.rotation().quaternion().coeffs();
  Eigen::Vector3d t = mounting.translation();
  double change = d;
  const RigDopplerCostFunction cost(point, earlier, motion, 1.0);
  double residual = 1.0;
  const double* blocks[] = {q.data(), t.data(), &change};
  ASSERT_TRUE(cost.Evaluate(blocks, &residual, nullptr));
  EXPECT_NEAR(residual, 0.0, 1e-12);
}

}  // namespace
}  // namespace radargauss
