// SPDX-License-Identifier: BSD-3-Clause
// Real spherical harmonics up to degree 3, with the constants, ordering and
// signs of the 3D Gaussian Splatting reference implementation (Kerbl et al.
// 2023): index l^2 + l + m for m = -l..l, Condon-Shortley phase included
// (so Y_1 = -C1 y, Y_2 = C1 z, Y_3 = -C1 x). The functions are orthonormal on
// the unit sphere. Templated on the scalar (double or ceres::Jet) and on the
// degree; a runtime-degree overload serves code that reads the degree from
// data. Directions must be unit vectors (the paper's incidence vector d).
#pragma once

#include <algorithm>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <Eigen/Core>

namespace radargauss {

inline constexpr int kMaxShDegree = 3;

// Number of SH functions up to and including `degree`: (degree + 1)^2.
constexpr int ShCoefficientCount(int degree) { return (degree + 1) * (degree + 1); }

namespace sh_constants {
inline constexpr double kC0 = 0.28209479177387814;
inline constexpr double kC1 = 0.4886025119029199;
inline constexpr double kC2[5] = {1.0925484305920792, -1.0925484305920792, 0.31539156525252005, -1.0925484305920792,
                                  0.5462742152960396};
inline constexpr double kC3[7] = {-0.5900435899266435, 2.890611442640554, -0.4570457994644658, 0.3731763325901154,
                                  -0.4570457994644658, 1.445305721320277, -0.5900435899266435};
}  // namespace sh_constants

// Writes Y_0(d) .. Y_{(Degree+1)^2 - 1}(d) to `basis`.
template <int Degree, typename T>
void EvaluateShBasis(const Eigen::Matrix<T, 3, 1>& d, T* basis) {
  static_assert(Degree >= 0 && Degree <= kMaxShDegree, "SH degree must be 0..3");
  using namespace sh_constants;
  basis[0] = T(kC0);
  if constexpr (Degree >= 1) {
    const T& x = d.x();
    const T& y = d.y();
    const T& z = d.z();
    basis[1] = -T(kC1) * y;
    basis[2] = T(kC1) * z;
    basis[3] = -T(kC1) * x;
    if constexpr (Degree >= 2) {
      const T xx = x * x;
      const T yy = y * y;
      const T zz = z * z;
      const T xy = x * y;
      const T yz = y * z;
      const T xz = x * z;
      basis[4] = T(kC2[0]) * xy;
      basis[5] = T(kC2[1]) * yz;
      basis[6] = T(kC2[2]) * (T(2.0) * zz - xx - yy);
      basis[7] = T(kC2[3]) * xz;
      basis[8] = T(kC2[4]) * (xx - yy);
      if constexpr (Degree >= 3) {
        basis[9] = T(kC3[0]) * y * (T(3.0) * xx - yy);
        basis[10] = T(kC3[1]) * xy * z;
        basis[11] = T(kC3[2]) * y * (T(4.0) * zz - xx - yy);
        basis[12] = T(kC3[3]) * z * (T(2.0) * zz - T(3.0) * xx - T(3.0) * yy);
        basis[13] = T(kC3[4]) * x * (T(4.0) * zz - xx - yy);
        basis[14] = T(kC3[5]) * z * (xx - yy);
        basis[15] = T(kC3[6]) * x * (xx - T(3.0) * yy);
      }
    }
  }
}

template <int Degree, typename T>
Eigen::Matrix<T, ShCoefficientCount(Degree), 1> ShBasis(const Eigen::Matrix<T, 3, 1>& d) {
  Eigen::Matrix<T, ShCoefficientCount(Degree), 1> basis;
  EvaluateShBasis<Degree>(d, basis.data());
  return basis;
}

// c . Y(d) with (Degree+1)^2 coefficients: the model's value in direction d,
// summed band by band from the coefficients scaled by their constants (the
// products of EvaluateShBasis, without the basis itself).
template <int Degree, typename T, typename CoefficientT>
T EvaluateSh(const CoefficientT* c, const Eigen::Matrix<T, 3, 1>& d) {
  static_assert(Degree >= 0 && Degree <= kMaxShDegree, "SH degree must be 0..3");
  using namespace sh_constants;
  T value = T(kC0) * T(c[0]);
  if constexpr (Degree >= 1) {
    const T& x = d.x();
    const T& y = d.y();
    const T& z = d.z();
    value += T(kC1) * (T(c[2]) * z - T(c[1]) * y - T(c[3]) * x);  // Y_1..3 = -C1 y, C1 z, -C1 x
    if constexpr (Degree >= 2) {
      const T xx = x * x, yy = y * y, zz = z * z;
      value += T(kC2[0] * c[4]) * (x * y) + T(kC2[1] * c[5]) * (y * z) + T(kC2[2] * c[6]) * (T(2.0) * zz - xx - yy) +
               T(kC2[3] * c[7]) * (x * z) + T(kC2[4] * c[8]) * (xx - yy);
      if constexpr (Degree >= 3) {
        value += T(kC3[0] * c[9]) * y * (T(3.0) * xx - yy) + T(kC3[1] * c[10]) * (x * y) * z +
                 T(kC3[2] * c[11]) * y * (T(4.0) * zz - xx - yy) +
                 T(kC3[3] * c[12]) * z * (T(2.0) * zz - T(3.0) * (xx + yy)) +
                 T(kC3[4] * c[13]) * x * (T(4.0) * zz - xx - yy) + T(kC3[5] * c[14]) * z * (xx - yy) +
                 T(kC3[6] * c[15]) * x * (xx - T(3.0) * yy);
      }
    }
  }
  return value;
}

// c . Y(d) (EvaluateSh) and its gradient c . dY/dd (polynomial forms, d not
// renormalised): the inner loop of the analytic RCS residual. The gradient
// is summed band by band from the coefficients scaled by their constants, so
// that no product with a zero entry of dY/dd is formed. Writes the basis
// Y(d) to `basis_out` when given.
template <int Degree>
double EvaluateShWithGradient(const double* c, const Eigen::Vector3d& d, Eigen::Vector3d& gradient,
                              double* basis_out = nullptr) {
  static_assert(Degree >= 0 && Degree <= kMaxShDegree, "SH degree must be 0..3");
  using namespace sh_constants;
  if (basis_out != nullptr) EvaluateShBasis<Degree>(d, basis_out);
  gradient.setZero();
  if constexpr (Degree >= 1) {
    const double x = d.x(), y = d.y(), z = d.z();
    gradient += kC1 * Eigen::Vector3d(-c[3], -c[1], c[2]);  // Y_1..3 = -C1 y, C1 z, -C1 x
    if constexpr (Degree >= 2) {
      const double b4 = kC2[0] * c[4], b5 = kC2[1] * c[5], b6 = kC2[2] * c[6], b7 = kC2[3] * c[7], b8 = kC2[4] * c[8];
      gradient += Eigen::Vector3d(b4 * y + b7 * z + 2.0 * (b8 - b6) * x, b4 * x + b5 * z - 2.0 * (b6 + b8) * y,
                                  b5 * y + b7 * x + 4.0 * b6 * z);
      if constexpr (Degree >= 3) {
        const double xx = x * x, yy = y * y, zz = z * z;
        const double xy = x * y, yz = y * z, xz = x * z;
        const double e9 = kC3[0] * c[9], e10 = kC3[1] * c[10], e11 = kC3[2] * c[11], e12 = kC3[3] * c[12],
                     e13 = kC3[4] * c[13], e14 = kC3[5] * c[14], e15 = kC3[6] * c[15];
        const double xx_yy = xx - yy, four_zz = 4.0 * zz;
        gradient +=
            Eigen::Vector3d((6.0 * e9 - 2.0 * e11) * xy + e10 * yz + (2.0 * e14 - 6.0 * e12) * xz +
                                e13 * (four_zz - 3.0 * xx - yy) + 3.0 * e15 * xx_yy,
                            3.0 * e9 * xx_yy + e10 * xz + e11 * (four_zz - xx - 3.0 * yy) -
                                2.0 * (3.0 * e12 + e14) * yz - 2.0 * (e13 + 3.0 * e15) * xy,
                            e10 * xy + 8.0 * (e11 * yz + e13 * xz) + e12 * (6.0 * zz - 3.0 * (xx + yy)) + e14 * xx_yy);
      }
    }
  }
  return EvaluateSh<Degree, double>(c, d);
}

// Calls f(std::integral_constant<int, degree>{}) for a degree read from data;
// throws std::invalid_argument for a degree outside 0..3.
template <typename F>
decltype(auto) WithShDegree(int degree, F&& f) {
  switch (degree) {
    case 0:
      return f(std::integral_constant<int, 0>{});
    case 1:
      return f(std::integral_constant<int, 1>{});
    case 2:
      return f(std::integral_constant<int, 2>{});
    case 3:
      return f(std::integral_constant<int, 3>{});
    default:
      throw std::invalid_argument("SH degree must be in 0..3, got " + std::to_string(degree));
  }
}

// Runtime-degree versions of the above.
template <typename T>
void EvaluateShBasis(int degree, const Eigen::Matrix<T, 3, 1>& d, T* basis) {
  WithShDegree(degree, [&](auto D) { EvaluateShBasis<decltype(D)::value>(d, basis); });
}

template <typename T, typename CoefficientT>
T EvaluateSh(int degree, const CoefficientT* coefficients, const Eigen::Matrix<T, 3, 1>& d) {
  return WithShDegree(degree, [&](auto D) { return EvaluateSh<decltype(D)::value, T>(coefficients, d); });
}

inline double EvaluateShWithGradient(int degree, const double* coefficients, const Eigen::Vector3d& d,
                                     Eigen::Vector3d& gradient, double* basis_out = nullptr) {
  return WithShDegree(
      degree, [&](auto D) { return EvaluateShWithGradient<decltype(D)::value>(coefficients, d, gradient, basis_out); });
}

}  // namespace radargauss
