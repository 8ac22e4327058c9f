// SPDX-License-Identifier: BSD-3-Clause
// Sufficient statistics of a Gaussian and of its RCS least squares, updated
// point by point (docs/design/odometry.md, "The incremental map"): adding, removing
// and merging members costs O(1) per point, and the Gaussian and the RCS
// model they give equal the batch fit of the same members.
#pragma once

#include <cstddef>

#include <Eigen/Core>

#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/core/sh.hpp"

namespace radargauss {

// Count, mean and scatter sum_i (p_i - mean)(p_i - mean)^T of a point set,
// updated by Welford's recurrence (no cancellation of large sums).
struct PointStatistics {
  std::size_t count = 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();

  void Add(const Eigen::Vector3d& point);
  // Takes out a point that was added; the statistics become those of the others.
  void Remove(const Eigen::Vector3d& point);
  void Merge(const PointStatistics& other);
  // The maximum-likelihood covariance scatter / count (build-map's).
  Eigen::Matrix3d Covariance() const { return scatter / double(count); }
};

// The normal equations of one Gaussian's RCS fit (paper eq. 2, docs/design/map.md,
// "RCS models") at degree kMaxShDegree: N = sum Y(d) Y(d)^T, r = sum Y(d) y,
// sum y^2, over the members that are inliers of a normalisation (median,
// scale) fixed when the statistics are (re)started. A lower degree's system is
// the leading block.
struct RcsStatistics {
  static constexpr int kSize = ShCoefficientCount(kMaxShDegree);
  RcsNormalisation normalisation;
  std::size_t inliers = 0;
  std::size_t outliers = 0;
  Eigen::Matrix<double, kSize, kSize> normal = Eigen::Matrix<double, kSize, kSize>::Zero();
  Eigen::Matrix<double, kSize, 1> rhs = Eigen::Matrix<double, kSize, 1>::Zero();
  double sum_y_squared = 0.0;

  // Empty statistics under `normalisation` (NormaliseRcs of the seed members).
  explicit RcsStatistics(const RcsNormalisation& normalisation = {}) : normalisation(normalisation) {}
  bool IsInlier(double rcs) const;
  // Adds a member of incidence direction d (unit, facing the radar); returns
  // whether it counted (an inlier).
  bool Add(const Eigen::Vector3d& direction, double rcs);
  // Takes out a member added before with the same direction and RCS.
  void Remove(const Eigen::Vector3d& direction, double rcs);
  // The model FitRcsModel fits from the same members: the same rank-revealing
  // decomposition on a square root of the normal equations (the degree
  // lowered while the rank is below half the coefficients).
  RcsModel Solve(const RcsFitOptions& options) const;
};

// KL(a || b), nats: how far Gaussian b, published before, is from a, its update.
double KullbackLeibler(const Eigen::Vector3d& mean_a, const Eigen::Matrix3d& covariance_a,
                       const Eigen::Vector3d& mean_b, const Eigen::Matrix3d& covariance_b);

}  // namespace radargauss
