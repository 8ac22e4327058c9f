// SPDX-License-Identifier: BSD-3-Clause
// SO3<T>: rotations in 3D as unit quaternions, templated on the scalar so
// that the same code runs on double and on ceres::Jet.
//
// Conventions (quaternion order x y z w, right perturbation) are those of
// radargauss/conventions.hpp. Invariant: the stored quaternion has unit norm.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace radargauss {

template <typename T>
class SO3 {
 public:
  using Scalar = T;
  using Tangent = Eigen::Matrix<T, 3, 1>;
  using Point = Eigen::Matrix<T, 3, 1>;
  using Matrix3 = Eigen::Matrix<T, 3, 3>;
  using Quaternion = Eigen::Quaternion<T>;

  // Below this squared angle Exp/Log use Taylor series (which keep Jet
  // derivatives finite and exact at zero); the Jacobians below kJacobianTaylor.
  static constexpr double kExpLogTaylorThetaSq = 1e-10;
  static constexpr double kJacobianTaylorThetaSq = 1e-6;

  SO3() : quaternion_(Quaternion::Identity()) {}

  // Normalises q; q must be non-zero.
  explicit SO3(const Quaternion& q) : quaternion_(q) { quaternion_.normalize(); }

  // From memory laid out x y z w (Ceres parameter blocks).
  static SO3 FromXyzw(const T* xyzw) { return SO3(Quaternion(xyzw[3], xyzw[0], xyzw[1], xyzw[2])); }

  // A quaternion of unit norm kept as it is, without normalising again (which
  // may move the last bit): a stored rotation reads back bit for bit.
  static SO3 FromUnitQuaternion(const Quaternion& q) {
    SO3 r;
    r.quaternion_ = q;
    return r;
  }

  // From a rotation matrix (orthonormal, det +1).
  static SO3 FromMatrix(const Matrix3& R) { return SO3(Quaternion(R)); }

  // Exp: so(3) -> SO(3), q = [sin(theta/2) phi/theta; cos(theta/2)].
  static SO3 Exp(const Tangent& phi) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const T theta_sq = phi.squaredNorm();
    T imag_factor;
    T real_factor;
    if (theta_sq < T(kExpLogTaylorThetaSq)) {
      const T theta_po4 = theta_sq * theta_sq;
      imag_factor = T(0.5) - theta_sq / T(48.0) + theta_po4 / T(3840.0);
      real_factor = T(1.0) - theta_sq / T(8.0) + theta_po4 / T(384.0);
    } else {
      const T theta = sqrt(theta_sq);
      const T half_theta = T(0.5) * theta;
      imag_factor = sin(half_theta) / theta;
      real_factor = cos(half_theta);
    }
    SO3 result;
    result.quaternion_ = Quaternion(real_factor, imag_factor * phi.x(), imag_factor * phi.y(), imag_factor * phi.z());
    return result;
  }

  // Log: SO(3) -> so(3), angle in [0, pi] (atan2-based, sign of w folded).
  Tangent Log() const {
    using std::atan2;
    using std::sqrt;
    const T squared_n = quaternion_.vec().squaredNorm();
    const T w = quaternion_.w();
    T two_atan_nbyw_by_n;
    if (squared_n < T(kExpLogTaylorThetaSq)) {
      // 2 atan(n/w) / n = 2/w - 2 n^2 / (3 w^3) + O(n^4).
      const T w_sq = w * w;
      two_atan_nbyw_by_n = T(2.0) / w - T(2.0 / 3.0) * squared_n / (w * w_sq);
    } else {
      const T n = sqrt(squared_n);
      const T atan_nbyw = (w < T(0.0)) ? T(-atan2(n, -w)) : T(atan2(n, w));
      two_atan_nbyw_by_n = T(2.0) * atan_nbyw / n;
    }
    return two_atan_nbyw_by_n * quaternion_.vec();
  }

  // hat: R^3 -> so(3), hat(a) b = a x b.
  static Matrix3 Hat(const Tangent& a) {
    Matrix3 m;
    m << T(0), -a.z(), a.y(),  //
        a.z(), T(0), -a.x(),   //
        -a.y(), a.x(), T(0);
    return m;
  }

  // vee: so(3) -> R^3, the inverse of Hat.
  static Tangent Vee(const Matrix3& m) { return Tangent(m(2, 1), m(0, 2), m(1, 0)); }

  // Ad(R) = R: Exp(Ad v) = R Exp(v) R^-1.
  Matrix3 Adjoint() const { return Matrix(); }

  // Right Jacobian: Exp(phi + d) = Exp(phi) Exp(Jr(phi) d) + O(|d|^2).
  // Jr = I - (1 - cos t)/t^2 [phi]x + (t - sin t)/t^3 [phi]x^2.
  static Matrix3 RightJacobian(const Tangent& phi) { return LeftJacobian(Tangent(-phi)); }

  // Left Jacobian: Exp(phi + d) = Exp(Jl(phi) d) Exp(phi) + O(|d|^2).
  static Matrix3 LeftJacobian(const Tangent& phi) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const T theta_sq = phi.squaredNorm();
    T a;  // (1 - cos t) / t^2
    T b;  // (t - sin t) / t^3
    if (theta_sq < T(kJacobianTaylorThetaSq)) {
      a = T(0.5) - theta_sq / T(24.0) + theta_sq * theta_sq / T(720.0);
      b = T(1.0 / 6.0) - theta_sq / T(120.0) + theta_sq * theta_sq / T(5040.0);
    } else {
      const T theta = sqrt(theta_sq);
      a = (T(1.0) - cos(theta)) / theta_sq;
      b = (theta - sin(theta)) / (theta_sq * theta);
    }
    const Matrix3 W = Hat(phi);
    return Matrix3::Identity() + a * W + b * W * W;
  }

  // Jl^-1 = I - 1/2 [phi]x + (1/t^2 - (1 + cos t)/(2 t sin t)) [phi]x^2.
  static Matrix3 LeftJacobianInverse(const Tangent& phi) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const T theta_sq = phi.squaredNorm();
    T c;
    if (theta_sq < T(kJacobianTaylorThetaSq)) {
      c = T(1.0 / 12.0) + theta_sq / T(720.0) + theta_sq * theta_sq / T(30240.0);
    } else {
      const T theta = sqrt(theta_sq);
      c = T(1.0) / theta_sq - (T(1.0) + cos(theta)) / (T(2.0) * theta * sin(theta));
    }
    const Matrix3 W = Hat(phi);
    return Matrix3::Identity() - T(0.5) * W + c * W * W;
  }

  static Matrix3 RightJacobianInverse(const Tangent& phi) { return LeftJacobianInverse(Tangent(-phi)); }

  SO3 operator*(const SO3& other) const {
    SO3 result;
    result.quaternion_ = quaternion_ * other.quaternion_;
    // Renormalise so that long products keep the unit-norm invariant.
    result.quaternion_.normalize();
    return result;
  }

  // Rotates a point: R p.
  Point operator*(const Point& p) const { return quaternion_ * p; }

  SO3 Inverse() const {
    SO3 result;
    result.quaternion_ = quaternion_.conjugate();
    return result;
  }

  // d(R Exp(d) p)/d d at d = 0 (right perturbation): -R [p]x.
  Matrix3 ActionJacobianRotation(const Point& p) const { return -Matrix() * Hat(p); }

  Matrix3 Matrix() const { return quaternion_.toRotationMatrix(); }
  const Quaternion& quaternion() const { return quaternion_; }
  const T* data() const { return quaternion_.coeffs().data(); }  // x y z w

  template <typename U>
  SO3<U> cast() const {
    return SO3<U>(quaternion_.template cast<U>());
  }

 private:
  Quaternion quaternion_;
};

using SO3d = SO3<double>;

}  // namespace radargauss
