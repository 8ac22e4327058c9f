// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/lie/se3.hpp"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <random>
#include <unsupported/Eigen/MatrixFunctions>

#include "support/test_util.hpp"

namespace radargauss {
namespace {

using testing::HardAngles;
using testing::NumericJacobian;
using testing::RandomUnitVector;
using Vector6d = Eigen::Matrix<double, 6, 1>;

std::vector<Vector6d> HardTangents() {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(-3.0, 3.0);
  std::vector<Vector6d> tangents;
  for (const double angle : HardAngles()) {
    for (int i = 0; i < 3; ++i) {
      Vector6d xi;
      xi.segment<3>(kTranslationOffset) = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
      xi.segment<3>(kRotationOffset) = angle * RandomUnitVector(rng);
      tangents.push_back(xi);
    }
  }
  return tangents;
}

// Independent reference: the matrix exponential of hat(xi).
TEST(SE3, ExpMatchesMatrixExponential) {
  for (const Vector6d& xi : HardTangents()) {
    const Eigen::Matrix4d expected = SE3d::Hat(xi).exp();
    EXPECT_LT((SE3d::Exp(xi).Matrix() - expected).norm(), 1e-12) << xi.transpose();
  }
}

TEST(SE3, LogInvertsExp) {
  for (const Vector6d& xi : HardTangents()) {
    // Near pi the translation part goes through Jl^-1, which amplifies
    // rounding; the tolerance reflects that.
    EXPECT_LT((SE3d::Exp(xi).Log() - xi).norm(), 1e-7) << xi.transpose();
  }
}

TEST(SE3, HatVee) {
  const Vector6d xi = (Vector6d() << 1, 2, 3, 4, 5, 6).finished();
  EXPECT_EQ(SE3d::Vee(SE3d::Hat(xi)), xi);
}

TEST(SE3, CompositionInverseAndAction) {
  const SE3d a = SE3d::Exp((Vector6d() << 1, -2, 0.5, 0.1, 0.2, -0.3).finished());
  const SE3d b = SE3d::Exp((Vector6d() << -0.3, 0.4, 2, -1.0, 0.4, 0.9).finished());
  const Eigen::Vector3d p(1.0, -2.0, 3.0);
  EXPECT_LT(((a * b) * p - a * (b * p)).norm(), 1e-13);
  EXPECT_LT(((a * b).Matrix() - a.Matrix() * b.Matrix()).norm(), 1e-13);
  EXPECT_LT(((a * a.Inverse()).Matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-14);
  EXPECT_LT((a * p - (a.rotation().Matrix() * p + a.translation())).norm(), 1e-14);
  EXPECT_LT((SE3d::FromMatrix(a.Matrix()).Matrix() - a.Matrix()).norm(), 1e-14);
}

TEST(SE3, AdjointConjugatesExp) {
  const SE3d x = SE3d::Exp((Vector6d() << 1, -2, 0.5, 0.5, -0.2, 1.1).finished());
  const Vector6d v = (Vector6d() << 0.3, 0.2, -0.1, 0.05, -0.02, 0.3).finished();
  const SE3d lhs = x * SE3d::Exp(v) * x.Inverse();
  EXPECT_LT((lhs.Matrix() - SE3d::Exp(x.Adjoint() * v).Matrix()).norm(), 1e-13);
}

TEST(SE3, RightAndLeftJacobiansMatchNumeric) {
  for (const Vector6d& xi : HardTangents()) {
    const SE3d x = SE3d::Exp(xi);
    const Eigen::MatrixXd jr_numeric = NumericJacobian(
        [&](const Eigen::VectorXd& d) { return Eigen::VectorXd((x.Inverse() * SE3d::Exp(xi + d)).Log()); },
        Vector6d::Zero());
    const Eigen::MatrixXd jl_numeric = NumericJacobian(
        [&](const Eigen::VectorXd& d) { return Eigen::VectorXd((SE3d::Exp(xi + d) * x.Inverse()).Log()); },
        Vector6d::Zero());
    EXPECT_LT((SE3d::RightJacobian(xi) - jr_numeric).norm(), 1e-6) << xi.transpose();
    EXPECT_LT((SE3d::LeftJacobian(xi) - jl_numeric).norm(), 1e-6) << xi.transpose();
  }
}

TEST(SE3, InverseJacobiansInvert) {
  for (const Vector6d& xi : HardTangents()) {
    using Matrix6d = Eigen::Matrix<double, 6, 6>;
    EXPECT_LT((SE3d::LeftJacobianInverse(xi) * SE3d::LeftJacobian(xi) - Matrix6d::Identity()).norm(), 1e-9)
        << xi.transpose();
    EXPECT_LT((SE3d::RightJacobianInverse(xi) * SE3d::RightJacobian(xi) - Matrix6d::Identity()).norm(), 1e-9)
        << xi.transpose();
  }
}

TEST(SE3, LogJacobiansMatchNumeric) {
  for (const Vector6d& xi : HardTangents()) {
    if (xi.segment<3>(kRotationOffset).norm() > 3.0) continue;  // the cut of Log at pi
    const SE3d x = SE3d::Exp(xi);
    const Eigen::MatrixXd right = NumericJacobian(
        [&](const Eigen::VectorXd& d) { return Eigen::VectorXd((x * SE3d::Exp(d)).Log()); }, Vector6d::Zero());
    EXPECT_LT((SE3d::RightJacobianInverse(xi) - right).norm(), 1e-6) << xi.transpose();
  }
}

TEST(SE3, ActionJacobianMatchesNumeric) {
  const Eigen::Vector3d p(2.0, -1.0, 0.5);
  for (const Vector6d& xi : HardTangents()) {
    const SE3d x = SE3d::Exp(xi);
    const Eigen::MatrixXd numeric = NumericJacobian(
        [&](const Eigen::VectorXd& d) { return Eigen::VectorXd(x * SE3d::Exp(d) * p); }, Vector6d::Zero());
    EXPECT_LT((x.ActionJacobian(p) - numeric).norm(), 1e-6) << xi.transpose();
  }
}

// Jets through SE3 Exp at exactly zero give d(R p + t)/d xi = [I, -[p]x].
TEST(SE3, JetDerivativesOfActionAtExactlyZero) {
  using Jet6 = ceres::Jet<double, 6>;
  Eigen::Matrix<Jet6, 6, 1> xi;
  for (int i = 0; i < 6; ++i) xi[i] = Jet6(0.0, i);
  const Eigen::Vector3d p(2.0, -1.0, 0.5);
  const Eigen::Matrix<Jet6, 3, 1> q = SE3<Jet6>::Exp(xi) * p.cast<Jet6>();
  Eigen::Matrix<double, 3, 6> dq;
  for (int i = 0; i < 3; ++i) dq.row(i) = q[i].v.transpose();
  EXPECT_LT((dq - SE3d().ActionJacobian(p)).norm(), 1e-15);
}

}  // namespace
}  // namespace radargauss
