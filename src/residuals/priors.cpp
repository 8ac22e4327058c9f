// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/residuals/priors.hpp"

#include <Eigen/Cholesky>

namespace radargauss {

Eigen::Matrix3d VelocitySqrtInformation(const Eigen::Matrix3d& velocity_covariance, double dt,
                                        const Eigen::Matrix3d& floor) {
  const Eigen::Matrix3d covariance = velocity_covariance * dt * dt + floor;
  const Eigen::Matrix3d L = covariance.llt().matrixL();
  return L.triangularView<Eigen::Lower>().solve(Eigen::Matrix3d::Identity());
}

}  // namespace radargauss
