// SPDX-License-Identifier: BSD-3-Clause
// The rotation term of odometry (docs/design/residuals.md, "The rotation term"): the
// scan's rotation against the motion model's prediction R_pred (the last
// rotation turned by the constant-rate or gyro increment),
//
//   r_w = W Log(R_pred^T R),   W = I / sigma,   sigma = rate_std * dt,
//
// 3 residuals on the rotation block; R_pred and W are constants of the term.
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "radargauss/lie/manifold.hpp"
#include "radargauss/lie/so3.hpp"
#include "radargauss/residuals/priors.hpp"

namespace radargauss {

class RotationResidual {
 public:
  RotationResidual(const SO3d& predicted, const Eigen::Matrix3d& sqrt_information)
      : predicted_inverse_(predicted.Inverse()), sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* rotation, T* residual) const {
    const SO3<T> error = predicted_inverse_.template cast<T>() * SO3<T>::FromXyzw(rotation);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = sqrt_information_.cast<T>() * error.Log();
    return true;
  }

  using AutoDiff = ceres::AutoDiffCostFunction<RotationResidual, 3, 4>;
  // Defined in src/residuals/autodiff_costs.cpp (docs/design.md, "Build").
  static ceres::CostFunction* Create(const SO3d& predicted, const Eigen::Matrix3d& sqrt_information);

 private:
  const SO3d predicted_inverse_;
  const Eigen::Matrix3d sqrt_information_;
};

// The analytic twin in the ambient x y z w: the residual depends on q / |q|
// only, so dr/dq = (W Jr^-1) 4 P^T with P the manifold's PlusJacobian
// (P^T P = I / 4 and P^T q = 0 for a unit q).
class RotationCostFunction final : public ceres::SizedCostFunction<3, 4> {
 public:
  explicit RotationCostFunction(const RotationPrior& prior) : prior_(prior) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const SO3d rotation = SO3d::FromXyzw(parameters[0]);
    Eigen::Map<Eigen::Vector3d> r(residuals);
    r = prior_.Residual(rotation);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Matrix<double, 4, 3, Eigen::RowMajor> P;
      SO3Manifold().PlusJacobian(parameters[0], P.data());
      Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> J(jacobians[0]);
      J = 4.0 * prior_.Jacobian(rotation) * P.transpose();
    }
    return true;
  }

 private:
  const RotationPrior prior_;
};

}  // namespace radargauss
