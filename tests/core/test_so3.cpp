// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/lie/so3.hpp"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <random>

#include "support/test_util.hpp"

namespace radargauss {
namespace {

using testing::HardAngles;
using testing::NumericJacobian;
using testing::RandomUnitVector;

// Tangent vectors at every hard angle, with a few random axes each.
std::vector<Eigen::Vector3d> HardTangents() {
  std::mt19937 rng(7);
  std::vector<Eigen::Vector3d> tangents;
  for (const double angle : HardAngles()) {
    for (int i = 0; i < 3; ++i) tangents.push_back(angle * RandomUnitVector(rng));
  }
  return tangents;
}

TEST(SO3, ExpMatchesAngleAxis) {
  for (const Eigen::Vector3d& phi : HardTangents()) {
    const double angle = phi.norm();
    const Eigen::Matrix3d expected =
        angle == 0.0 ? Eigen::Matrix3d::Identity() : Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix();
    EXPECT_LT((SO3d::Exp(phi).Matrix() - expected).norm(), 1e-14) << phi.transpose();
  }
}

TEST(SO3, LogInvertsExp) {
  for (const Eigen::Vector3d& phi : HardTangents()) {
    EXPECT_LT((SO3d::Exp(phi).Log() - phi).norm(), 1e-9) << phi.transpose();
  }
}

TEST(SO3, LogFoldsNegativeW) {
  // q and -q are the same rotation; Log must give the angle in [0, pi].
  const Eigen::Vector3d phi(0.2, -0.4, 0.1);
  const SO3d r = SO3d::Exp(phi);
  const SO3d flipped(Eigen::Quaterniond(-r.quaternion().coeffs()));
  EXPECT_LT((flipped.Log() - phi).norm(), 1e-14);
}

TEST(SO3, HatVee) {
  const Eigen::Vector3d a(0.3, -1.2, 2.0);
  const Eigen::Vector3d b(-0.7, 0.1, 0.5);
  EXPECT_LT((SO3d::Hat(a) * b - a.cross(b)).norm(), 1e-15);
  EXPECT_EQ(SO3d::Vee(SO3d::Hat(a)), a);
}

TEST(SO3, CompositionInverseAndAction) {
  const SO3d a = SO3d::Exp(Eigen::Vector3d(0.1, 0.2, -0.3));
  const SO3d b = SO3d::Exp(Eigen::Vector3d(-1.0, 0.4, 0.9));
  const Eigen::Vector3d p(1.0, -2.0, 3.0);
  EXPECT_LT(((a * b) * p - a * (b * p)).norm(), 1e-14);
  EXPECT_LT(((a * b).Matrix() - a.Matrix() * b.Matrix()).norm(), 1e-14);
  EXPECT_LT((a.Inverse() * (a * p) - p).norm(), 1e-14);
  EXPECT_LT((a.Matrix() * a.Matrix().transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-14);
}

TEST(SO3, AdjointConjugatesExp) {
  const SO3d r = SO3d::Exp(Eigen::Vector3d(0.5, -0.2, 1.1));
  const Eigen::Vector3d v(0.3, 0.2, -0.1);
  const SO3d lhs = r * SO3d::Exp(v) * r.Inverse();
  EXPECT_LT((lhs.Matrix() - SO3d::Exp(r.Adjoint() * v).Matrix()).norm(), 1e-14);
}

// Jr: Exp(phi + d) = Exp(phi) Exp(Jr d), so Jr = d/dd Log(Exp(phi)^-1 Exp(phi + d)).
TEST(SO3, RightAndLeftJacobiansMatchNumeric) {
  for (const Eigen::Vector3d& phi : HardTangents()) {
    const SO3d r = SO3d::Exp(phi);
    const Eigen::MatrixXd jr_numeric = NumericJacobian(
        [&](const Eigen::VectorXd& d) { return Eigen::VectorXd((r.Inverse() * SO3d::Exp(phi + d)).Log()); },
        Eigen::Vector3d::Zero());
    const Eigen::MatrixXd jl_numeric = NumericJacobian(
        [&](const Eigen::VectorXd& d) { return Eigen::VectorXd((SO3d::Exp(phi + d) * r.Inverse()).Log()); },
        Eigen::Vector3d::Zero());
    EXPECT_LT((SO3d::RightJacobian(phi) - jr_numeric).norm(), 1e-6) << phi.transpose();
    EXPECT_LT((SO3d::LeftJacobian(phi) - jl_numeric).norm(), 1e-6) << phi.transpose();
  }
}

TEST(SO3, InverseJacobiansInvert) {
  for (const Eigen::Vector3d& phi : HardTangents()) {
    EXPECT_LT((SO3d::RightJacobianInverse(phi) * SO3d::RightJacobian(phi) - Eigen::Matrix3d::Identity()).norm(), 1e-9)
        << phi.transpose();
    EXPECT_LT((SO3d::LeftJacobianInverse(phi) * SO3d::LeftJacobian(phi) - Eigen::Matrix3d::Identity()).norm(), 1e-9)
        << phi.transpose();
  }
}

// Log's Jacobians: Log(Exp(phi) Exp(d)) = phi + Jr^-1 d, Log(Exp(d) Exp(phi)) =
// phi + Jl^-1 d. Not at pi - 1e-6, where a finite step crosses the cut of Log.
TEST(SO3, LogJacobiansMatchNumeric) {
  for (const Eigen::Vector3d& phi : HardTangents()) {
    if (phi.norm() > 3.0) continue;
    const SO3d r = SO3d::Exp(phi);
    const Eigen::MatrixXd right = NumericJacobian(
        [&](const Eigen::VectorXd& d) { return Eigen::VectorXd((r * SO3d::Exp(d)).Log()); }, Eigen::Vector3d::Zero());
    const Eigen::MatrixXd left = NumericJacobian(
        [&](const Eigen::VectorXd& d) { return Eigen::VectorXd((SO3d::Exp(d) * r).Log()); }, Eigen::Vector3d::Zero());
    EXPECT_LT((SO3d::RightJacobianInverse(phi) - right).norm(), 1e-6) << phi.transpose();
    EXPECT_LT((SO3d::LeftJacobianInverse(phi) - left).norm(), 1e-6) << phi.transpose();
  }
}

TEST(SO3, ActionJacobianMatchesNumeric) {
  const Eigen::Vector3d p(2.0, -1.0, 0.5);
  for (const Eigen::Vector3d& phi : HardTangents()) {
    const SO3d r = SO3d::Exp(phi);
    const Eigen::MatrixXd numeric = NumericJacobian(
        [&](const Eigen::VectorXd& d) { return Eigen::VectorXd(r * SO3d::Exp(d) * p); }, Eigen::Vector3d::Zero());
    EXPECT_LT((r.ActionJacobianRotation(p) - numeric).norm(), 1e-6) << phi.transpose();
  }
}

using Jet3 = ceres::Jet<double, 3>;
using Jet4 = ceres::Jet<double, 4>;

// At exactly zero, Jet derivatives of the quaternion must be 1/2 [I; 0] (the
// analytic d Exp/d phi at 0), not NaN or zero.
TEST(SO3, JetDerivativesOfExpAtExactlyZero) {
  const Eigen::Matrix<Jet3, 3, 1> phi(Jet3(0.0, 0), Jet3(0.0, 1), Jet3(0.0, 2));
  const SO3<Jet3> r = SO3<Jet3>::Exp(phi);
  const Eigen::Vector4d xyzw_values(r.data()[0].a, r.data()[1].a, r.data()[2].a, r.data()[3].a);
  EXPECT_EQ(xyzw_values, Eigen::Vector4d(0, 0, 0, 1));
  Eigen::Matrix<double, 4, 3> dq;
  for (int i = 0; i < 4; ++i) dq.row(i) = r.data()[i].v.transpose();
  Eigen::Matrix<double, 4, 3> expected = Eigen::Matrix<double, 4, 3>::Zero();
  expected.topRows<3>() = 0.5 * Eigen::Matrix3d::Identity();
  EXPECT_LT((dq - expected).norm(), 1e-15);
}

// d Log/d q at the identity quaternion is [2 I, 0] (analytic); Jets must agree.
TEST(SO3, JetDerivativesOfLogAtIdentity) {
  const Eigen::Quaternion<Jet4> q(Jet4(1.0, 3), Jet4(0.0, 0), Jet4(0.0, 1), Jet4(0.0, 2));
  const SO3<Jet4> r(q);
  const Eigen::Matrix<Jet4, 3, 1> phi = r.Log();
  Eigen::Matrix<double, 3, 4> dphi;
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(phi[i].a, 0.0);
    dphi.row(i) = phi[i].v.transpose();
  }
  Eigen::Matrix<double, 3, 4> expected = Eigen::Matrix<double, 3, 4>::Zero();
  expected.leftCols<3>() = 2.0 * Eigen::Matrix3d::Identity();
  EXPECT_LT((dphi - expected).norm(), 1e-15);
}

// Jets through Log(Exp(phi)) at every hard angle give the identity Jacobian
// (up to the cut at pi), and Jets of Exp agree with numeric derivatives.
TEST(SO3, JetDerivativesThroughExpLogAreConsistent) {
  for (const Eigen::Vector3d& phi_value : HardTangents()) {
    if (phi_value.norm() > 3.0) continue;
    Eigen::Matrix<Jet3, 3, 1> phi;
    for (int i = 0; i < 3; ++i) phi[i] = Jet3(phi_value[i], i);
    const Eigen::Matrix<Jet3, 3, 1> round_trip = SO3<Jet3>::Exp(phi).Log();
    Eigen::Matrix3d d;
    for (int i = 0; i < 3; ++i) d.row(i) = round_trip[i].v.transpose();
    EXPECT_LT((d - Eigen::Matrix3d::Identity()).norm(), 1e-9) << phi_value.transpose();

    const SO3<Jet3> r = SO3<Jet3>::Exp(phi);
    Eigen::Matrix<double, 4, 3> dq;
    for (int i = 0; i < 4; ++i) dq.row(i) = r.data()[i].v.transpose();
    const Eigen::MatrixXd numeric = NumericJacobian(
        [](const Eigen::VectorXd& x) { return Eigen::VectorXd(SO3d::Exp(x).quaternion().coeffs()); }, phi_value);
    EXPECT_LT((dq - numeric).norm(), 1e-8) << phi_value.transpose();
  }
}

}  // namespace
}  // namespace radargauss
