// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/map/gaussian_statistics.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

namespace radargauss {

void PointStatistics::Add(const Eigen::Vector3d& point) {
  ++count;
  const Eigen::Vector3d delta = point - mean;
  mean += delta / double(count);
  scatter += (double(count - 1) / double(count)) * (delta * delta.transpose());
}

void PointStatistics::Remove(const Eigen::Vector3d& point) {
  if (count <= 1) {
    *this = PointStatistics();
    return;
  }
  // The inverse of Add: the others' mean, then the point's share of the scatter.
  const double n = double(count);
  const Eigen::Vector3d others = (n * mean - point) / (n - 1.0);
  const Eigen::Vector3d delta = point - others;
  scatter -= ((n - 1.0) / n) * (delta * delta.transpose());
  mean = others;
  --count;
}

void PointStatistics::Merge(const PointStatistics& other) {
  if (other.count == 0) return;
  if (count == 0) {
    *this = other;
    return;
  }
  const double n = double(count), m = double(other.count);
  const Eigen::Vector3d delta = other.mean - mean;
  scatter += other.scatter + (n * m / (n + m)) * (delta * delta.transpose());
  mean += (m / (n + m)) * delta;
  count += other.count;
}

bool RcsStatistics::IsInlier(double rcs) const {
  return normalisation.valid && std::abs(rcs - normalisation.median) <= normalisation.scale;
}

namespace {

Eigen::Matrix<double, RcsStatistics::kSize, 1> Basis(const Eigen::Vector3d& direction) {
  Eigen::Matrix<double, RcsStatistics::kSize, 1> values;
  EvaluateShBasis<kMaxShDegree>(direction, values.data());
  return values;
}

}  // namespace

bool RcsStatistics::Add(const Eigen::Vector3d& direction, double rcs) {
  if (!IsInlier(rcs)) {
    ++outliers;
    return false;
  }
  const double y = (rcs - normalisation.median) / normalisation.scale;
  const Eigen::Matrix<double, kSize, 1> basis = Basis(direction);
  normal.selfadjointView<Eigen::Lower>().rankUpdate(basis);
  rhs += y * basis;
  sum_y_squared += y * y;
  ++inliers;
  return true;
}

void RcsStatistics::Remove(const Eigen::Vector3d& direction, double rcs) {
  if (!IsInlier(rcs)) {
    outliers -= outliers > 0;
    return;
  }
  const double y = (rcs - normalisation.median) / normalisation.scale;
  const Eigen::Matrix<double, kSize, 1> basis = Basis(direction);
  normal.selfadjointView<Eigen::Lower>().rankUpdate(basis, -1.0);
  rhs -= y * basis;
  sum_y_squared -= y * y;
  inliers -= inliers > 0;
}

RcsModel RcsStatistics::Solve(const RcsFitOptions& options) const {
  RcsModel model;
  if (!normalisation.valid || inliers == 0) return model;
  model.median = normalisation.median;
  model.scale = normalisation.scale;
  return FitAdaptiveDegree(model, inliers, options, [&](int degree, RcsModel& fit) {
    const int count = ShCoefficientCount(degree);
    // A square root M^T M = N and M^T z = r: min |M c - z| is the members'
    // least squares, and the pivoted QR of M has the R of the members'
    // basis matrix (it depends on N alone), so the decomposition keeps and
    // truncates the directions FitRcsModel does.
    const Eigen::MatrixXd block = normal.topLeftCorner(count, count).selfadjointView<Eigen::Lower>();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(block);
    const Eigen::VectorXd roots = solver.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    const Eigen::MatrixXd root = roots.asDiagonal() * solver.eigenvectors().transpose();
    Eigen::VectorXd z = solver.eigenvectors().transpose() * rhs.head(count);
    for (int j = 0; j < count; ++j) z[j] = roots[j] > 0.0 ? z[j] / roots[j] : 0.0;
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
    cod.setThreshold(options.rank_threshold);
    cod.compute(root);
    if (cod.rank() < std::max(1, count / 2) && options.adaptive) return false;
    const Eigen::VectorXd c = cod.solve(z);
    fit.degree = degree;
    fit.coefficients.fill(0.0);
    for (int j = 0; j < count; ++j) fit.coefficients[j] = c[j];
    // |A c - y|^2 = sum y^2 - 2 c.r + c^T N c
    const double residual = sum_y_squared - 2.0 * c.dot(rhs.head(count)) + c.dot(block * c);
    fit.fit_rmse = std::sqrt(std::max(residual, 0.0) / double(inliers));
    fit.inliers = std::uint32_t(inliers);
    // Sum of (y - mean y)^2: Y_0 is the constant kC0, so sum y = rhs_0 / kC0.
    const double sum_y = rhs[0] / sh_constants::kC0;
    SetRcsFitSpread(fit, residual, sum_y_squared - sum_y * sum_y / double(inliers), inliers, count);
    // Without the members: the offset of a log-normal spread, sigma^2 ln(10) / 20 dB.
    fit.mean_offset_db = fit.spread_db * fit.spread_db * std::log(10.0) / 20.0;
    return true;
  });
}

double KullbackLeibler(const Eigen::Vector3d& mean_a, const Eigen::Matrix3d& covariance_a,
                       const Eigen::Vector3d& mean_b, const Eigen::Matrix3d& covariance_b) {
  const Eigen::LLT<Eigen::Matrix3d> b(covariance_b);
  const Eigen::Vector3d delta = mean_a - mean_b;
  const double trace = b.solve(covariance_a).trace();
  const double mahalanobis_sq = delta.dot(b.solve(delta));
  const double log_det_ratio = std::log(covariance_b.determinant() / covariance_a.determinant());
  return 0.5 * (trace + mahalanobis_sq - 3.0 + log_det_ratio);
}

}  // namespace radargauss
