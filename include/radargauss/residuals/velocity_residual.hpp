// SPDX-License-Identifier: BSD-3-Clause
// The Doppler velocity term of odometry (docs/design/residuals.md, "The velocity term"):
// the translation since the previous scan, in the previous scan's radar
// frame, against the Doppler velocity times the time step,
//
//   r_v = W (R_prev^T (t - t_prev) - v dt),   W^T W = (S dt^2 + Q)^-1,
//
// 3 residuals on the translation block; R_prev, t_prev, v, dt and W are
// constants of the term (S: the velocity's covariance, Q: a floor).
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "radargauss/lie/se3.hpp"
#include "radargauss/residuals/priors.hpp"

namespace radargauss {

class VelocityResidual {
 public:
  VelocityResidual(const SE3d& previous, const Eigen::Vector3d& velocity, double dt,
                   const Eigen::Matrix3d& sqrt_information)
      : rotation_previous_t_(previous.rotation().Matrix().transpose()),
        translation_previous_(previous.translation()),
        displacement_(velocity * dt),
        sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* translation, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(translation);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = sqrt_information_.cast<T>() *
        (rotation_previous_t_.cast<T>() * (t - translation_previous_.cast<T>()) - displacement_.cast<T>());
    return true;
  }

  using AutoDiff = ceres::AutoDiffCostFunction<VelocityResidual, 3, 3>;
  // Defined in src/residuals/autodiff_costs.cpp (docs/design.md, "Build").
  static ceres::CostFunction* Create(const SE3d& previous, const Eigen::Vector3d& velocity, double dt,
                                     const Eigen::Matrix3d& sqrt_information);

 private:
  const Eigen::Matrix3d rotation_previous_t_;
  const Eigen::Vector3d translation_previous_;
  const Eigen::Vector3d displacement_;  // v dt
  const Eigen::Matrix3d sqrt_information_;
};

// The analytic twin: dr/dt = W R_prev^T.
class VelocityCostFunction final : public ceres::SizedCostFunction<3, 3> {
 public:
  VelocityCostFunction(const SE3d& previous, const Eigen::Vector3d& velocity, double dt,
                       const Eigen::Matrix3d& sqrt_information)
      : jacobian_(sqrt_information * previous.rotation().Matrix().transpose()),
        offset_(-(jacobian_ * previous.translation()) - sqrt_information * velocity * dt) {}

  explicit VelocityCostFunction(const VelocityPrior& prior)
      : VelocityCostFunction(prior.previous, prior.displacement, 1.0, prior.sqrt_information) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    Eigen::Map<Eigen::Vector3d> r(residuals);
    r = jacobian_ * Eigen::Map<const Eigen::Vector3d>(parameters[0]) + offset_;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> J(jacobians[0]);
      J = jacobian_;
    }
    return true;
  }

 private:
  const Eigen::Matrix3d jacobian_;  // W R_prev^T
  const Eigen::Vector3d offset_;    // -W (R_prev^T t_prev + v dt)
};

}  // namespace radargauss
