// SPDX-License-Identifier: BSD-3-Clause
// The normal equations of eq. 2 for fixed correspondences (docs/design/solvers.md,
// "The own Gauss-Newton"): per term H += w J^T J and g += w J^T r over the
// tangent [dt; dphi], w the loss's IRLS weight rho'(s); the geometric sums
// in closed form (two terms per SIMD lane pair) or with Jets through the
// Ceres functors. The own Gauss-Newton solves them; every solver's result
// carries their H at the final pose as its information matrix.
#pragma once

#include <Eigen/Core>

#include "radargauss/solvers/correspondences.hpp"

namespace radargauss {

// One linearisation: H = sum w J^T J, g = sum w J^T r over the tangent
// [dt; dphi], and the number of residuals.
struct LinearSystem {
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  std::size_t residuals = 0;
  double rho_sum = 0.0;  // sum of rho(s) over the residuals: the term's cost before eq. 2's weight
  // With `loss_curvature` (GaussNewtonOptions): what the losses' curvature adds
  // to H (sum of c (J^T r)(J^T r)^T, c = max(2 rho'', -rho'/s)); else zero.
  Eigen::Matrix<double, 6, 6> loss_curvature = Eigen::Matrix<double, 6, 6>::Zero();
};

// The geometric and RCS systems at `pose` for fixed correspondences (public
// so that tests and benchmarks can compare the analytic and autodiff paths).
LinearSystem BuildGeometricSystem(const Correspondences& correspondences, const SE3d& pose,
                                  const ScanMatchingOptions& options, bool loss_curvature = false);
LinearSystem BuildRcsSystem(const Correspondences& correspondences, const SE3d& pose,
                            const ScanMatchingOptions& options, bool loss_curvature = false);

// Eq. 2's weighted sum: H = (1-w)/N_geo H_geo + w/N_rcs H_rcs, likewise g,
// the loss curvature and the cost f, plus the terms of `priors`; a term with
// weight 0 is not built.
struct CombinedSystem {
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 6> loss_curvature = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  double cost = 0.0;  // f of eq. 2 at the pose, as EvaluateCost
};
CombinedSystem BuildCombinedSystem(const Correspondences& correspondences, const SE3d& pose,
                                   const ScanMatchingOptions& options, const ScanPriors& priors,
                                   bool loss_curvature = false);

// ScanMatchingResult::information: the combined H with IRLS weights, the
// rotation-only RCS term's identity translation block left out.
Eigen::Matrix<double, 6, 6> InformationMatrix(const Correspondences& correspondences, const SE3d& pose,
                                              const ScanMatchingOptions& options);

// ScanMatchingResult::covariance: the pose's covariance over [dt; dphi] from
// the geometric residuals themselves, A^-1 B A^-1 with A = sum w J^T S J
// (S = Sigma^-1) and B = sum over Gaussians c of u_c u_c^T, u_c = sum over
// the Gaussian's terms of w J^T S e: residuals sharing a Gaussian may be
// correlated (its mean is one estimate), those of different Gaussians are
// taken as independent (docs/design/solvers.md, "The match's covariance").
// Scaled by G / (G - 1) for G Gaussians. Zero with fewer than 7 Gaussians
// or a singular A.
Eigen::Matrix<double, 6, 6> MatchCovariance(const Correspondences& correspondences, const SE3d& pose,
                                            const ScanMatchingOptions& options);

}  // namespace radargauss
