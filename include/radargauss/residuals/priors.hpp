// SPDX-License-Identifier: BSD-3-Clause
// The terms odometry adds to eq. 2 for one scan, as plain values: the
// Doppler velocity term (docs/design/residuals.md, "The velocity term") and the
// rotation term (docs/design/residuals.md, "The rotation term"). They are arguments of
// a match (ScanMatcher::Match), not options: they change with every scan.
// Their Ceres functors are residuals/velocity_residual.hpp and
// residuals/rotation_residual.hpp.
#pragma once

#include <optional>

#include <Eigen/Core>

#include "radargauss/lie/se3.hpp"
#include "radargauss/lie/so3.hpp"

namespace radargauss {

// W = L^-1 with L L^T = S dt^2 + Q (Cholesky), so W^T W = (S dt^2 + Q)^-1;
// the floor Q must make the sum positive definite.
Eigen::Matrix3d VelocitySqrtInformation(const Eigen::Matrix3d& velocity_covariance, double dt,
                                        const Eigen::Matrix3d& floor);

// The velocity term as scan matching adds it to eq. 2: weight * |r_v|^2.
struct VelocityPrior {
  SE3d previous;                                                   // (R_prev, t_prev)
  Eigen::Vector3d displacement = Eigen::Vector3d::Zero();          // v dt, previous radar frame
  Eigen::Matrix3d sqrt_information = Eigen::Matrix3d::Identity();  // W
  double weight = 1.0;                                             // 0: off
  Eigen::Matrix3d Jacobian() const { return sqrt_information * previous.rotation().Matrix().transpose(); }
  Eigen::Vector3d Residual(const Eigen::Vector3d& translation) const {
    return sqrt_information *
           (previous.rotation().Matrix().transpose() * (translation - previous.translation()) - displacement);
  }
};

// The rotation term as scan matching adds it to eq. 2: weight * |r_w|^2.
struct RotationPrior {
  SO3d predicted;                                                  // R_pred
  Eigen::Matrix3d sqrt_information = Eigen::Matrix3d::Identity();  // W
  double weight = 1.0;                                             // 0: off
  Eigen::Vector3d Residual(const SO3d& rotation) const {
    return sqrt_information * (predicted.Inverse() * rotation).Log();
  }
  // d r_w / d dphi for R Exp(dphi) (right perturbation): W Jr^-1(Log(R_pred^T R)).
  Eigen::Matrix3d Jacobian(const SO3d& rotation) const {
    return sqrt_information * SO3d::RightJacobianInverse((predicted.Inverse() * rotation).Log());
  }
};

// The terms of one scan: none by default (eq. 2 alone).
struct ScanPriors {
  std::optional<VelocityPrior> velocity;
  std::optional<RotationPrior> rotation;
};

}  // namespace radargauss
