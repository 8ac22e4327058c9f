// SPDX-License-Identifier: BSD-3-Clause
// The geometric residual of scan matching (paper section III-B, docs/design/residuals.md,
// "Residuals"), for a radar point p associated to the Gaussian (mu, Sigma):
//
//   r_geo = L^T (R p + t - mu),   Sigma^-1 = L L^T,
//
// so ||r_geo||^2 is the Mahalanobis^2 distance. Parameters: the rotation
// block (quaternion x y z w, SO3Manifold) and the translation block (R^3).
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>

#include <memory>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "radargauss/residuals/quaternion_jacobians.hpp"

namespace radargauss {

class GeometricResidual {
 public:
  GeometricResidual(const Eigen::Vector3d& point_radar, const Eigen::Vector3d& mean,
                    const Eigen::Matrix3d& sqrt_information_t)
      : point_radar_(point_radar), mean_(mean), sqrt_information_t_(sqrt_information_t) {}

  template <typename T>
  bool operator()(const T* rotation, const T* translation, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(rotation);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(translation);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = sqrt_information_t_.cast<T>() * (q * point_radar_.cast<T>() + t - mean_.cast<T>());
    return true;
  }

  // Re-targets the residual at another term (problems kept across associations).
  void Reset(const Eigen::Vector3d& point_radar, const Eigen::Vector3d& mean,
             const Eigen::Matrix3d& sqrt_information_t) {
    *this = GeometricResidual(point_radar, mean, sqrt_information_t);
  }

  using AutoDiff = ceres::AutoDiffCostFunction<GeometricResidual, 3, 4, 3>;
  // Defined in src/residuals/autodiff_costs.cpp (docs/design.md, "Build").
  static ceres::CostFunction* Create(const Eigen::Vector3d& point_radar, const Eigen::Vector3d& mean,
                                     const Eigen::Matrix3d& sqrt_information_t);
  // The same around a functor the caller keeps a pointer to (for Reset).
  static ceres::CostFunction* Create(std::unique_ptr<GeometricResidual> functor);

 private:
  Eigen::Vector3d point_radar_;
  Eigen::Vector3d mean_;
  Eigen::Matrix3d sqrt_information_t_;
};

// The analytic twin: same residual, Jacobians in closed form
// (d r / d q = L^T d(R p)/d q, d r / d t = L^T).
class GeometricCostFunction final : public ceres::SizedCostFunction<3, 4, 3> {
 public:
  GeometricCostFunction(const Eigen::Vector3d& point_radar, const Eigen::Vector3d& mean,
                        const Eigen::Matrix3d& sqrt_information_t)
      : point_radar_(point_radar), mean_(mean), sqrt_information_t_(sqrt_information_t) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Eigen::Map<const Eigen::Quaterniond> q(parameters[0]);
    const Eigen::Map<const Eigen::Vector3d> t(parameters[1]);
    Eigen::Map<Eigen::Vector3d> r(residuals);
    r = sqrt_information_t_ * (q * point_radar_ + t - mean_);
    if (jacobians == nullptr) return true;
    if (jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> J(jacobians[0]);
      J = sqrt_information_t_ * RotatePointJacobian(parameters[0], point_radar_);
    }
    if (jacobians[1] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> J(jacobians[1]);
      J = sqrt_information_t_;
    }
    return true;
  }

  void Reset(const Eigen::Vector3d& point_radar, const Eigen::Vector3d& mean,
             const Eigen::Matrix3d& sqrt_information_t) {
    point_radar_ = point_radar;
    mean_ = mean;
    sqrt_information_t_ = sqrt_information_t;
  }

 private:
  Eigen::Vector3d point_radar_;
  Eigen::Vector3d mean_;
  Eigen::Matrix3d sqrt_information_t_;
};

}  // namespace radargauss
