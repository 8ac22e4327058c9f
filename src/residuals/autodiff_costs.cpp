// SPDX-License-Identifier: BSD-3-Clause
// The automatic-differentiation twins of the residuals, made here once: an
// AutoDiffCostFunction instantiated in a header would be instantiated again
// in every file that includes it (docs/design.md, "Build").
#include <ceres/dynamic_autodiff_cost_function.h>

#include <memory>

#include "radargauss/residuals/geometric_residual.hpp"
#include "radargauss/residuals/imu_residual.hpp"
#include "radargauss/residuals/radar_inertial_residuals.hpp"
#include "radargauss/residuals/rcs_residual.hpp"
#include "radargauss/residuals/relative_pose_residual.hpp"
#include "radargauss/residuals/rig_doppler_residual.hpp"
#include "radargauss/residuals/rotation_residual.hpp"
#include "radargauss/residuals/velocity_residual.hpp"

namespace radargauss {

ceres::CostFunction* GeometricResidual::Create(const Eigen::Vector3d& point_radar, const Eigen::Vector3d& mean,
                                               const Eigen::Matrix3d& sqrt_information_t) {
  return Create(std::make_unique<GeometricResidual>(point_radar, mean, sqrt_information_t));
}

ceres::CostFunction* GeometricResidual::Create(std::unique_ptr<GeometricResidual> functor) {
  return new AutoDiff(functor.release());
}

ceres::CostFunction* RcsResidual::Create(const RcsTerm& term) { return Create(std::make_unique<RcsResidual>(term)); }

ceres::CostFunction* RcsResidual::Create(std::unique_ptr<RcsResidual> functor) {
  return new AutoDiff(functor.release());
}

ceres::CostFunction* RcsRotationResidual::Create(const RcsTerm& term, const Eigen::Vector3d& translation) {
  return Create(std::make_unique<RcsRotationResidual>(term, translation));
}

ceres::CostFunction* RcsRotationResidual::Create(std::unique_ptr<RcsRotationResidual> functor) {
  return new AutoDiff(functor.release());
}

ceres::CostFunction* RcsCoefficientResidual::Create(const RcsTerm& term, const Eigen::Vector3d& translation,
                                                    bool full) {
  auto* cost = new AutoDiff(new RcsCoefficientResidual(term, translation, full));
  cost->AddParameterBlock(4);
  cost->AddParameterBlock(ShCoefficientCount(term.degree));
  if (full) cost->AddParameterBlock(3);
  cost->SetNumResiduals(1);
  return cost;
}

ceres::CostFunction* RelativePoseResidual::Create(const SE3d& measured,
                                                  const Eigen::Matrix<double, 6, 6>& sqrt_information) {
  return new AutoDiff(new RelativePoseResidual(measured, sqrt_information));
}

ceres::CostFunction* RigDopplerResidual::Create(const Eigen::Vector3d& direction, double doppler,
                                                const ReferenceMotion& motion, double sqrt_information) {
  return new AutoDiff(new RigDopplerResidual(direction, doppler, motion, sqrt_information));
}

ceres::CostFunction* RigPointResidual::Create(const Eigen::Vector3d& point, const Eigen::Vector3d& mean,
                                              const Eigen::Matrix3d& sqrt_information_t,
                                              const ReferenceMotion& motion) {
  return new AutoDiff(new RigPointResidual(point, mean, sqrt_information_t, motion));
}

ceres::CostFunction* RotationResidual::Create(const SO3d& predicted, const Eigen::Matrix3d& sqrt_information) {
  return new AutoDiff(new RotationResidual(predicted, sqrt_information));
}

ceres::CostFunction* VelocityResidual::Create(const SE3d& previous, const Eigen::Vector3d& velocity, double dt,
                                              const Eigen::Matrix3d& sqrt_information) {
  return new AutoDiff(new VelocityResidual(previous, velocity, dt, sqrt_information));
}

ceres::CostFunction* ImuResidual::Create(const ImuPreintegration& preintegration, const ImuNoise& noise,
                                         const Eigen::Vector3d& gravity) {
  return new AutoDiff(new ImuResidual(preintegration, noise, gravity));
}

ceres::CostFunction* RadarPoseResidual::Create(const SE3d& measured,
                                               const Eigen::Matrix<double, 6, 6>& sqrt_information,
                                               const ImuAtScan& imu) {
  return new AutoDiff(new RadarPoseResidual(measured, sqrt_information, imu));
}

ceres::CostFunction* RadarVelocityResidual::Create(const Eigen::Vector3d& radar_velocity,
                                                   const Eigen::Matrix3d& sqrt_information, const ImuAtScan& imu,
                                                   double elevation_bias_removed) {
  return new AutoDiff(new RadarVelocityResidual(radar_velocity, sqrt_information, imu, elevation_bias_removed));
}

ceres::CostFunction* VehicleMotionResidual::Create(double sigma) {
  return new AutoDiff(new VehicleMotionResidual(sigma));
}

}  // namespace radargauss
