// SPDX-License-Identifier: BSD-3-Clause
// SE3<T>: rigid transforms (R, t) acting as q = R p + t, templated on the
// scalar (double or ceres::Jet).
//
// Tangent order [rho; phi] and right perturbation as in
// radargauss/conventions.hpp. Exp([rho; phi]) = (Exp(phi), Jl(phi) rho).
#pragma once

#include <cmath>

#include "radargauss/core/conventions.hpp"
#include "radargauss/lie/so3.hpp"

namespace radargauss {

template <typename T>
class SE3 {
 public:
  using Scalar = T;
  using Tangent = Eigen::Matrix<T, 6, 1>;
  using Vector3 = Eigen::Matrix<T, 3, 1>;
  using Point = Eigen::Matrix<T, 3, 1>;
  using Matrix3 = Eigen::Matrix<T, 3, 3>;
  using Matrix4 = Eigen::Matrix<T, 4, 4>;
  using Matrix6 = Eigen::Matrix<T, 6, 6>;
  using Matrix3x6 = Eigen::Matrix<T, 3, 6>;

  SE3() : rotation_(), translation_(Vector3::Zero()) {}
  SE3(const SO3<T>& rotation, const Vector3& translation) : rotation_(rotation), translation_(translation) {}

  // From memory laid out qx qy qz qw tx ty tz (the SE3Manifold block).
  static SE3 FromData(const T* data) { return SE3(SO3<T>::FromXyzw(data), Vector3(data[4], data[5], data[6])); }

  // From a homogeneous 4x4 matrix whose top-left block is a rotation.
  static SE3 FromMatrix(const Matrix4& m) {
    return SE3(SO3<T>::FromMatrix(m.template topLeftCorner<3, 3>()), m.template topRightCorner<3, 1>());
  }

  static SE3 Exp(const Tangent& xi) {
    const Vector3 rho = xi.template segment<3>(kTranslationOffset);
    const Vector3 phi = xi.template segment<3>(kRotationOffset);
    return SE3(SO3<T>::Exp(phi), SO3<T>::LeftJacobian(phi) * rho);
  }

  Tangent Log() const {
    const Vector3 phi = rotation_.Log();
    Tangent xi;
    xi.template segment<3>(kTranslationOffset) = SO3<T>::LeftJacobianInverse(phi) * translation_;
    xi.template segment<3>(kRotationOffset) = phi;
    return xi;
  }

  // hat: R^6 -> se(3) as a 4x4 matrix [[hat(phi), rho], [0, 0]].
  static Matrix4 Hat(const Tangent& xi) {
    Matrix4 m = Matrix4::Zero();
    m.template topLeftCorner<3, 3>() = SO3<T>::Hat(xi.template segment<3>(kRotationOffset));
    m.template topRightCorner<3, 1>() = xi.template segment<3>(kTranslationOffset);
    return m;
  }

  static Tangent Vee(const Matrix4& m) {
    Tangent xi;
    xi.template segment<3>(kTranslationOffset) = m.template topRightCorner<3, 1>();
    xi.template segment<3>(kRotationOffset) = SO3<T>::Vee(m.template topLeftCorner<3, 3>());
    return xi;
  }

  // Ad(X) = [[R, [t]x R], [0, R]]: Exp(Ad xi) = X Exp(xi) X^-1.
  Matrix6 Adjoint() const {
    const Matrix3 R = rotation_.Matrix();
    Matrix6 ad = Matrix6::Zero();
    ad.template block<3, 3>(kTranslationOffset, kTranslationOffset) = R;
    ad.template block<3, 3>(kTranslationOffset, kRotationOffset) = SO3<T>::Hat(translation_) * R;
    ad.template block<3, 3>(kRotationOffset, kRotationOffset) = R;
    return ad;
  }

  // Left Jacobian: Exp(xi + d) = Exp(Jl(xi) d) Exp(xi) + O(|d|^2).
  // Jl = [[Jl(phi), Q(rho, phi)], [0, Jl(phi)]] (Barfoot, State Estimation, 7.86).
  static Matrix6 LeftJacobian(const Tangent& xi) {
    const Vector3 phi = xi.template segment<3>(kRotationOffset);
    const Matrix3 jl = SO3<T>::LeftJacobian(phi);
    Matrix6 J = Matrix6::Zero();
    J.template block<3, 3>(kTranslationOffset, kTranslationOffset) = jl;
    J.template block<3, 3>(kTranslationOffset, kRotationOffset) = QMatrix(xi);
    J.template block<3, 3>(kRotationOffset, kRotationOffset) = jl;
    return J;
  }

  // Right Jacobian: Exp(xi + d) = Exp(xi) Exp(Jr(xi) d); Jr(xi) = Jl(-xi).
  static Matrix6 RightJacobian(const Tangent& xi) { return LeftJacobian(Tangent(-xi)); }

  // Jl^-1 = [[Jl^-1, -Jl^-1 Q Jl^-1], [0, Jl^-1]].
  static Matrix6 LeftJacobianInverse(const Tangent& xi) {
    const Vector3 phi = xi.template segment<3>(kRotationOffset);
    const Matrix3 jl_inv = SO3<T>::LeftJacobianInverse(phi);
    Matrix6 J = Matrix6::Zero();
    J.template block<3, 3>(kTranslationOffset, kTranslationOffset) = jl_inv;
    J.template block<3, 3>(kTranslationOffset, kRotationOffset) = -jl_inv * QMatrix(xi) * jl_inv;
    J.template block<3, 3>(kRotationOffset, kRotationOffset) = jl_inv;
    return J;
  }

  static Matrix6 RightJacobianInverse(const Tangent& xi) { return LeftJacobianInverse(Tangent(-xi)); }

  SE3 operator*(const SE3& other) const {
    return SE3(rotation_ * other.rotation_, rotation_ * other.translation_ + translation_);
  }

  // Action on a point: R p + t.
  Point operator*(const Point& p) const { return rotation_ * p + translation_; }

  SE3 Inverse() const {
    const SO3<T> r_inv = rotation_.Inverse();
    return SE3(r_inv, -(r_inv * translation_));
  }

  // d(X Exp(d) p)/d d at d = 0: [R, -R [p]x] (columns in tangent order).
  Matrix3x6 ActionJacobian(const Point& p) const {
    Matrix3x6 J;
    J.template block<3, 3>(0, kTranslationOffset) = rotation_.Matrix();
    J.template block<3, 3>(0, kRotationOffset) = rotation_.ActionJacobianRotation(p);
    return J;
  }

  Matrix4 Matrix() const {
    Matrix4 m = Matrix4::Identity();
    m.template topLeftCorner<3, 3>() = rotation_.Matrix();
    m.template topRightCorner<3, 1>() = translation_;
    return m;
  }

  const SO3<T>& rotation() const { return rotation_; }
  const Vector3& translation() const { return translation_; }
  SO3<T>& rotation() { return rotation_; }
  Vector3& translation() { return translation_; }

  template <typename U>
  SE3<U> cast() const {
    return SE3<U>(rotation_.template cast<U>(), translation_.template cast<U>());
  }

 private:
  // Q(rho, phi), the coupling block of the SE3 left Jacobian.
  static Matrix3 QMatrix(const Tangent& xi) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const Vector3 rho = xi.template segment<3>(kTranslationOffset);
    const Vector3 phi = xi.template segment<3>(kRotationOffset);
    const T theta_sq = phi.squaredNorm();
    T a;  // (t - sin t) / t^3
    T b;  // (t^2 + 2 cos t - 2) / (2 t^4)
    T c;  // (2 t - 3 sin t + t cos t) / (2 t^5)
    // The closed forms cancel catastrophically for small angles: use series.
    if (theta_sq < T(1e-2)) {
      const T t2 = theta_sq;
      const T t4 = t2 * t2;
      const T t6 = t4 * t2;
      a = T(1.0 / 6.0) - t2 / T(120.0) + t4 / T(5040.0) - t6 / T(362880.0);
      b = T(1.0 / 24.0) - t2 / T(720.0) + t4 / T(40320.0) - t6 / T(3628800.0);
      c = T(1.0 / 120.0) - t2 / T(2520.0) + t4 / T(120960.0) - t6 / T(9979200.0);
    } else {
      const T theta = sqrt(theta_sq);
      const T s = sin(theta);
      const T co = cos(theta);
      a = (theta - s) / (theta_sq * theta);
      b = (theta_sq + T(2.0) * co - T(2.0)) / (T(2.0) * theta_sq * theta_sq);
      c = (T(2.0) * theta - T(3.0) * s + theta * co) / (T(2.0) * theta_sq * theta_sq * theta);
    }
    const Matrix3 V = SO3<T>::Hat(rho);
    const Matrix3 W = SO3<T>::Hat(phi);
    const Matrix3 WV = W * V;
    const Matrix3 VW = V * W;
    const Matrix3 WVW = WV * W;
    return T(0.5) * V + a * (WV + VW + WVW) + b * (W * WV + VW * W - T(3.0) * WVW) + c * (WVW * W + W * WVW);
  }

  SO3<T> rotation_;
  Vector3 translation_;
};

using SE3d = SE3<double>;

}  // namespace radargauss
