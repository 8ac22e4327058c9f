// SPDX-License-Identifier: BSD-3-Clause
// The relative-pose term of the pose graph (docs/design/solvers.md, "The pose graph"):
// keyframes i and j at T_i, T_j (world from keyframe) and a measured
// relative pose Z_ij (frame i from frame j) give the error transform
//
//   E = Z_ij^-1 T_i^-1 T_j,   r = W [ t_E ; Log(R_E) ],
//
// translation first (docs/design.md, "Conventions"), W a square root of the
// measurement's information. Blocks: R_i (x y z w), t_i, R_j, t_j.
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "radargauss/core/conventions.hpp"
#include "radargauss/lie/se3.hpp"

namespace radargauss {

class RelativePoseResidual {
 public:
  RelativePoseResidual(const SE3d& measured, const Eigen::Matrix<double, 6, 6>& sqrt_information)
      : measured_inverse_(measured.Inverse()), sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* rotation_i, const T* translation_i, const T* rotation_j, const T* translation_j,
                  T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const SO3<T> Ri_inverse = SO3<T>::FromXyzw(rotation_i).Inverse();
    const SO3<T> Rz_inverse = measured_inverse_.rotation().template cast<T>();
    const Vector3 ti = Eigen::Map<const Vector3>(translation_i);
    const Vector3 tj = Eigen::Map<const Vector3>(translation_j);
    Eigen::Matrix<T, 6, 1> error;
    error.template segment<3>(kTranslationOffset) =
        Rz_inverse * (Ri_inverse * (tj - ti)) + measured_inverse_.translation().template cast<T>();
    error.template segment<3>(kRotationOffset) = (Rz_inverse * Ri_inverse * SO3<T>::FromXyzw(rotation_j)).Log();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residual);
    r = sqrt_information_.cast<T>() * error;
    return true;
  }

  using AutoDiff = ceres::AutoDiffCostFunction<RelativePoseResidual, 6, 4, 3, 4, 3>;
  // Defined in src/residuals/autodiff_costs.cpp (docs/design.md, "Build").
  static ceres::CostFunction* Create(const SE3d& measured, const Eigen::Matrix<double, 6, 6>& sqrt_information);

 private:
  const SE3d measured_inverse_;
  const Eigen::Matrix<double, 6, 6> sqrt_information_;
};

// The analytic twin. With d = R_i^T (t_j - t_i), e = Log(R_E) and right
// perturbations R Exp(phi), t + dt: dt_E/dt_j = -dt_E/dt_i = R_z^T R_i^T,
// dt_E/dphi_i = R_z^T [d]x, de/dphi_j = Jr^-1(e), de/dphi_i = -Jr^-1(e) R_j^T R_i;
// in the ambient quaternion, times 4 P^T (residuals/rotation_residual.hpp).
class RelativePoseCostFunction final : public ceres::SizedCostFunction<6, 4, 3, 4, 3> {
 public:
  RelativePoseCostFunction(const SE3d& measured, const Eigen::Matrix<double, 6, 6>& sqrt_information)
      : measured_inverse_(measured.Inverse()), sqrt_information_(sqrt_information) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  const SE3d measured_inverse_;
  const Eigen::Matrix<double, 6, 6> sqrt_information_;
};

}  // namespace radargauss
