// SPDX-License-Identifier: BSD-3-Clause
// Ceres manifolds for SO3 and SE3 with the right perturbation of
// radargauss/conventions.hpp: Plus(x, d) = x * Exp(d), Minus(y, x) = Log(x^-1 y).
//
// SO3Manifold: ambient x y z w (unit quaternion), tangent phi (3).
// SE3Manifold: ambient qx qy qz qw tx ty tz (7), tangent [rho; phi] (6).
// Minus keeps the quaternion's sign (see internal::SignPreservingLog).
#pragma once

#include <cmath>

#include <ceres/manifold.h>

#include "radargauss/lie/se3.hpp"

namespace radargauss {

namespace internal {

// 2 atan2(|v|, w) v / |v| for q = (v, w): the inverse of Exp on the quaternion
// itself, sign included (angle in [0, 2 pi)), so that Plus(x, Minus(y, x))
// returns the ambient vector y and not -y, as Ceres's QuaternionManifold.
// SO3::Log folds the sign instead (angle in [0, pi]), which is right for the
// group but not for this ambient-space invariant.
inline Eigen::Vector3d SignPreservingLog(const Eigen::Quaterniond& q) {
  const double squared_n = q.vec().squaredNorm();
  if (squared_n < SO3d::kExpLogTaylorThetaSq) return SO3d(q).Log();
  const double n = std::sqrt(squared_n);
  return (2.0 * std::atan2(n, q.w()) / n) * q.vec();
}

}  // namespace internal

class SO3Manifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 4; }
  int TangentSize() const override { return 3; }

  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    const SO3d result = SO3d::FromXyzw(x) * SO3d::Exp(Eigen::Map<const Eigen::Vector3d>(delta));
    Eigen::Map<Eigen::Vector4d> out(x_plus_delta);
    out = result.quaternion().coeffs();
    return true;
  }

  // d(x * Exp(d))/dd at d = 0 = 1/2 [[w I + [v]x], [-v^T]] for x = (v, w).
  bool PlusJacobian(const double* x, double* jacobian) const override {
    const Eigen::Map<const Eigen::Vector3d> v(x);
    const double w = x[3];
    Eigen::Map<Eigen::Matrix<double, 4, 3, Eigen::RowMajor>> J(jacobian);
    J.topRows<3>() = 0.5 * (w * Eigen::Matrix3d::Identity() + SO3d::Hat(v));
    J.bottomRows<1>() = -0.5 * v.transpose();
    return true;
  }

  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    Eigen::Map<Eigen::Vector3d> out(y_minus_x);
    out = internal::SignPreservingLog((SO3d::FromXyzw(x).Inverse() * SO3d::FromXyzw(y)).quaternion());
    return true;
  }

  // d Log(x^-1 y)/dy at y = x = 2 [w I - [v]x, -v] for x = (v, w).
  bool MinusJacobian(const double* x, double* jacobian) const override {
    const Eigen::Map<const Eigen::Vector3d> v(x);
    const double w = x[3];
    Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> J(jacobian);
    J.leftCols<3>() = 2.0 * (w * Eigen::Matrix3d::Identity() - SO3d::Hat(v));
    J.rightCols<1>() = -2.0 * v;
    return true;
  }
};

class SE3Manifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }

  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    const SE3d result = SE3d::FromData(x) * SE3d::Exp(Eigen::Map<const Eigen::Matrix<double, 6, 1>>(delta));
    Eigen::Map<Eigen::Vector4d> out_rotation(x_plus_delta);
    Eigen::Map<Eigen::Vector3d> out_translation(x_plus_delta + 4);
    out_rotation = result.rotation().quaternion().coeffs();
    out_translation = result.translation();
    return true;
  }

  // Quaternion rows take the SO3 PlusJacobian on the phi columns; translation
  // rows take R on the rho columns (Jl(0) = I).
  bool PlusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    Eigen::Matrix<double, 4, 3, Eigen::RowMajor> j_rot;
    so3_.PlusJacobian(x, j_rot.data());
    J.block<4, 3>(0, kRotationOffset) = j_rot;
    J.block<3, 3>(4, kTranslationOffset) = SO3d::FromXyzw(x).Matrix();
    return true;
  }

  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    Eigen::Map<Eigen::Matrix<double, 6, 1>> out(y_minus_x);
    const SE3d relative = SE3d::FromData(x).Inverse() * SE3d::FromData(y);
    const Eigen::Vector3d phi = internal::SignPreservingLog(relative.rotation().quaternion());
    out.segment<3>(kTranslationOffset) = SO3d::LeftJacobianInverse(phi) * relative.translation();
    out.segment<3>(kRotationOffset) = phi;
    return true;
  }

  bool MinusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    Eigen::Matrix<double, 3, 4, Eigen::RowMajor> j_rot;
    so3_.MinusJacobian(x, j_rot.data());
    J.block<3, 4>(kRotationOffset, 0) = j_rot;
    J.block<3, 3>(kTranslationOffset, 4) = SO3d::FromXyzw(x).Matrix().transpose();
    return true;
  }

 private:
  SO3Manifold so3_;
};

}  // namespace radargauss
