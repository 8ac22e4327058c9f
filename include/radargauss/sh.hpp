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
inline constexpr double kC2[5] = {1.0925484305920792, -1.0925484305920792, 0.31539156525252005,
                                  -1.0925484305920792, 0.5462742152960396};
inline constexpr double kC3[7] = {-0.5900435899266435, 2.890611442640554, -0.4570457994644658,
                                  0.3731763325901154,  -0.4570457994644658, 1.445305721320277,
                                  -0.5900435899266435};
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

// c . Y(d) with (Degree+1)^2 coefficients: the model's value in direction d.
template <int Degree, typename T, typename CoefficientT>
T EvaluateSh(const CoefficientT* coefficients, const Eigen::Matrix<T, 3, 1>& d) {
  T basis[ShCoefficientCount(Degree)];
  EvaluateShBasis<Degree>(d, basis);
  T value = T(0.0);
  for (int i = 0; i < ShCoefficientCount(Degree); ++i) value += T(coefficients[i]) * basis[i];
  return value;
}

// Gradient of each basis function with respect to the direction components:
// gradient[3 * i + k] = dY_i / dd_k, for the polynomial forms above (d is not
// renormalised). The analytic twin of the Jet derivatives of EvaluateShBasis.
template <int Degree>
void EvaluateShBasisGradient(const Eigen::Vector3d& d, double* gradient) {
  static_assert(Degree >= 0 && Degree <= kMaxShDegree, "SH degree must be 0..3");
  using namespace sh_constants;
  const auto set = [gradient](int i, double gx, double gy, double gz) {
    gradient[3 * i] = gx;
    gradient[3 * i + 1] = gy;
    gradient[3 * i + 2] = gz;
  };
  set(0, 0.0, 0.0, 0.0);
  if constexpr (Degree >= 1) {
    const double x = d.x(), y = d.y(), z = d.z();
    set(1, 0.0, -kC1, 0.0);
    set(2, 0.0, 0.0, kC1);
    set(3, -kC1, 0.0, 0.0);
    if constexpr (Degree >= 2) {
      set(4, kC2[0] * y, kC2[0] * x, 0.0);
      set(5, 0.0, kC2[1] * z, kC2[1] * y);
      set(6, -2.0 * kC2[2] * x, -2.0 * kC2[2] * y, 4.0 * kC2[2] * z);
      set(7, kC2[3] * z, 0.0, kC2[3] * x);
      set(8, 2.0 * kC2[4] * x, -2.0 * kC2[4] * y, 0.0);
      if constexpr (Degree >= 3) {
        const double xx = x * x, yy = y * y, zz = z * z;
        set(9, 6.0 * kC3[0] * x * y, 3.0 * kC3[0] * (xx - yy), 0.0);
        set(10, kC3[1] * y * z, kC3[1] * x * z, kC3[1] * x * y);
        set(11, -2.0 * kC3[2] * x * y, kC3[2] * (4.0 * zz - xx - 3.0 * yy), 8.0 * kC3[2] * y * z);
        set(12, -6.0 * kC3[3] * x * z, -6.0 * kC3[3] * y * z, kC3[3] * (6.0 * zz - 3.0 * xx - 3.0 * yy));
        set(13, kC3[4] * (4.0 * zz - 3.0 * xx - yy), -2.0 * kC3[4] * x * y, 8.0 * kC3[4] * x * z);
        set(14, 2.0 * kC3[5] * x * z, -2.0 * kC3[5] * y * z, kC3[5] * (xx - yy));
        set(15, 3.0 * kC3[6] * (xx - yy), -6.0 * kC3[6] * x * y, 0.0);
      }
    }
  }
}

// c . Y(d) and its gradient c . dY/dd (polynomial forms, d not renormalised)
// in one pass: the inner loop of the analytic RCS residual. With the degree
// fixed, the basis and its gradient stay in registers. Writes the basis
// Y(d) to `basis_out` when given.
template <int Degree>
double EvaluateShWithGradient(const double* coefficients, const Eigen::Vector3d& d, Eigen::Vector3d& gradient,
                              double* basis_out = nullptr) {
  constexpr int kCount = ShCoefficientCount(Degree);
  double basis[kCount];
  double basis_gradient[3 * kCount];
  EvaluateShBasis<Degree>(d, basis);
  EvaluateShBasisGradient<Degree>(d, basis_gradient);
  double value = 0.0;
  gradient.setZero();
  for (int i = 0; i < kCount; ++i) {
    value += coefficients[i] * basis[i];
    gradient += coefficients[i] * Eigen::Map<const Eigen::Vector3d>(basis_gradient + 3 * i);
  }
  if (basis_out != nullptr) std::copy(basis, basis + kCount, basis_out);
  return value;
}

// Calls f(std::integral_constant<int, degree>{}) for a degree read from data;
// throws std::invalid_argument for a degree outside 0..3.
template <typename F>
decltype(auto) WithShDegree(int degree, F&& f) {
  switch (degree) {
    case 0: return f(std::integral_constant<int, 0>{});
    case 1: return f(std::integral_constant<int, 1>{});
    case 2: return f(std::integral_constant<int, 2>{});
    case 3: return f(std::integral_constant<int, 3>{});
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
  return WithShDegree(degree, [&](auto D) {
    return EvaluateShWithGradient<decltype(D)::value>(coefficients, d, gradient, basis_out);
  });
}

}  // namespace radargauss
