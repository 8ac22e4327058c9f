// SPDX-License-Identifier: BSD-3-Clause
// The residuals of a rig's calibration (docs/design/rig.md, "Calibration of a
// rig"): a static point seen by one radar of the rig, its Doppler and its
// position, as residuals of that radar's extrinsic and clock offset.
//
// The Doppler. The radar sits at T_ref_radar = (R, t) in the reference radar's
// frame. The reference moves with velocity v and angular velocity w (its
// frame) at the scan's time on the body's clock. A change of the radar's clock
// offset by d moves that time by -d, where v and w change at rates a and alpha:
//
//   r = s (v_d + (R u)^T V),   V = v - a d + (w - alpha d) x t,
//
// u the point's unit direction (radar frame), v_d its Doppler (positive
// receding, conventions.hpp) and s = 1 / sigma_d. Parameters: the rotation
// (quaternion x y z w, SO3Manifold), the translation (R^3) and the change of
// the clock offset d (s).
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "radargauss/residuals/quaternion_jacobians.hpp"

namespace radargauss {

// The reference radar's motion at a scan's time, and its rate of change.
struct ReferenceMotion {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();              // v, m/s
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();      // w, rad/s
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();          // a = dv/dt, m/s^2
  Eigen::Vector3d angular_acceleration = Eigen::Vector3d::Zero();  // alpha = dw/dt, rad/s^2
};

class RigDopplerResidual {
 public:
  RigDopplerResidual(const Eigen::Vector3d& direction, double doppler, const ReferenceMotion& motion,
                     double sqrt_information)
      : direction_(direction.normalized()), doppler_(doppler), motion_(motion), scale_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* rotation, const T* translation, const T* clock_change, T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Eigen::Quaternion<T>> q(rotation);
    const Eigen::Map<const Vector3> t(translation);
    const T d = clock_change[0];
    const Vector3 w = motion_.angular_velocity.cast<T>() - motion_.angular_acceleration.cast<T>() * d;
    const Vector3 V = motion_.velocity.cast<T>() - motion_.acceleration.cast<T>() * d + w.cross(t);
    residual[0] = T(scale_) * (T(doppler_) + (q * direction_.cast<T>()).dot(V));
    return true;
  }

  using AutoDiff = ceres::AutoDiffCostFunction<RigDopplerResidual, 1, 4, 3, 1>;
  // Defined in src/residuals/autodiff_costs.cpp (docs/design.md, "Build").
  static ceres::CostFunction* Create(const Eigen::Vector3d& direction, double doppler, const ReferenceMotion& motion,
                                     double sqrt_information);

 private:
  Eigen::Vector3d direction_;
  double doppler_;
  ReferenceMotion motion_;
  double scale_;
};

// The analytic twin, with b = R u:
//   dr/dq = s V^T d(R u)/dq,   dr/dt = s b^T [w - alpha d]x,   dr/dd = -s b^T (a + alpha x t).
class RigDopplerCostFunction final : public ceres::SizedCostFunction<1, 4, 3, 1> {
 public:
  RigDopplerCostFunction(const Eigen::Vector3d& direction, double doppler, const ReferenceMotion& motion,
                         double sqrt_information)
      : direction_(direction.normalized()), doppler_(doppler), motion_(motion), scale_(sqrt_information) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Eigen::Map<const Eigen::Quaterniond> q(parameters[0]);
    const Eigen::Map<const Eigen::Vector3d> t(parameters[1]);
    const double d = parameters[2][0];
    const Eigen::Vector3d w = motion_.angular_velocity - motion_.angular_acceleration * d;
    const Eigen::Vector3d V = motion_.velocity - motion_.acceleration * d + w.cross(t);
    const Eigen::Vector3d b = q * direction_;
    residuals[0] = scale_ * (doppler_ + b.dot(V));
    if (jacobians == nullptr) return true;
    if (jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 1, 4>> J(jacobians[0]);
      J = scale_ * V.transpose() * RotatePointJacobian(parameters[0], direction_);
    }
    if (jacobians[1] != nullptr) {  // b . (w x t) = (b x w) . t
      Eigen::Map<Eigen::Matrix<double, 1, 3>> J(jacobians[1]);
      J = scale_ * b.cross(w).transpose();
    }
    if (jacobians[2] != nullptr) {
      jacobians[2][0] = -scale_ * b.dot(motion_.acceleration + motion_.angular_acceleration.cross(t));
    }
    return true;
  }

 private:
  Eigen::Vector3d direction_;
  double doppler_;
  ReferenceMotion motion_;
  double scale_;
};

// The position: the point p (radar frame) against its Gaussian (mu, Sigma)
// of the reference's map, brought into the reference's frame at the scan's
// time (mean m, L'^T = L^T R_world_ref). A clock offset larger by d places
// the point where the reference was d earlier, to first order in d:
//
//   r = L'^T (y - d (v + w x y) - m),   y = R p + t,
//
// 3 residuals on the rotation, the translation and the clock change.
class RigPointResidual {
 public:
  RigPointResidual(const Eigen::Vector3d& point, const Eigen::Vector3d& mean, const Eigen::Matrix3d& sqrt_information_t,
                   const ReferenceMotion& motion)
      : point_(point), mean_(mean), sqrt_information_t_(sqrt_information_t), motion_(motion) {}

  template <typename T>
  bool operator()(const T* rotation, const T* translation, const T* clock_change, T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Eigen::Quaternion<T>> q(rotation);
    const Vector3 y = q * point_.cast<T>() + Eigen::Map<const Vector3>(translation);
    const Vector3 moved =
        y - clock_change[0] * (motion_.velocity.cast<T>() + motion_.angular_velocity.cast<T>().cross(y));
    Eigen::Map<Vector3> r(residual);
    r = sqrt_information_t_.cast<T>() * (moved - mean_.cast<T>());
    return true;
  }

  using AutoDiff = ceres::AutoDiffCostFunction<RigPointResidual, 3, 4, 3, 1>;
  // Defined in src/residuals/autodiff_costs.cpp (docs/design.md, "Build").
  static ceres::CostFunction* Create(const Eigen::Vector3d& point, const Eigen::Vector3d& mean,
                                     const Eigen::Matrix3d& sqrt_information_t, const ReferenceMotion& motion);

 private:
  Eigen::Vector3d point_, mean_;
  Eigen::Matrix3d sqrt_information_t_;
  ReferenceMotion motion_;
};

// The analytic twin, with A = L'^T (I - d [w]x):
//   dr/dq = A d(R p)/dq,   dr/dt = A,   dr/dd = -L'^T (v + w x y).
class RigPointCostFunction final : public ceres::SizedCostFunction<3, 4, 3, 1> {
 public:
  RigPointCostFunction(const Eigen::Vector3d& point, const Eigen::Vector3d& mean,
                       const Eigen::Matrix3d& sqrt_information_t, const ReferenceMotion& motion)
      : point_(point), mean_(mean), sqrt_information_t_(sqrt_information_t), motion_(motion) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Eigen::Map<const Eigen::Quaterniond> q(parameters[0]);
    const Eigen::Vector3d y = q * point_ + Eigen::Map<const Eigen::Vector3d>(parameters[1]);
    const double d = parameters[2][0];
    const Eigen::Vector3d rate = motion_.velocity + motion_.angular_velocity.cross(y);
    Eigen::Map<Eigen::Vector3d> r(residuals);
    r = sqrt_information_t_ * (y - d * rate - mean_);
    if (jacobians == nullptr) return true;
    const Eigen::Matrix3d A =
        sqrt_information_t_ * (Eigen::Matrix3d::Identity() - d * SO3d::Hat(motion_.angular_velocity));
    if (jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> J(jacobians[0]);
      J = A * RotatePointJacobian(parameters[0], point_);
    }
    if (jacobians[1] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> J(jacobians[1]);
      J = A;
    }
    if (jacobians[2] != nullptr) {
      Eigen::Map<Eigen::Vector3d> J(jacobians[2]);
      J = -sqrt_information_t_ * rate;
    }
    return true;
  }

 private:
  Eigen::Vector3d point_, mean_;
  Eigen::Matrix3d sqrt_information_t_;
  ReferenceMotion motion_;
};

}  // namespace radargauss
