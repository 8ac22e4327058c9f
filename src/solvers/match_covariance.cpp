// SPDX-License-Identifier: BSD-3-Clause
// The match's covariance from its own residuals (docs/design/solvers.md,
// "The match's covariance").
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>

#include "radargauss/core/conventions.hpp"
#include "radargauss/residuals/robust_loss.hpp"
#include "radargauss/solvers/normal_equations.hpp"

namespace radargauss {

Eigen::Matrix<double, 6, 6> MatchCovariance(const Correspondences& c, const SE3d& pose,
                                            const ScanMatchingOptions& options) {
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  std::vector<std::pair<std::uint32_t, Vector6d>> scores;  // (Gaussian, w J^T S e) per term
  scores.reserve(c.geometric.size());
  LossSum loss(options.geometric_loss);
  const Eigen::Matrix3d R = pose.rotation().Matrix();
  for (const GeometricTerm& term : c.geometric) {
    // e = R p + t - mu; de/ddt = I, de/ddphi = -R [p]x (right perturbation).
    const Eigen::Matrix3d S = c.index->Information(term.gaussian);
    const Eigen::Vector3d e = R * term.point_radar + pose.translation() - c.index->Mean(term.gaussian);
    Eigen::Matrix<double, 3, 6> J;
    J.block<3, 3>(0, kTranslationOffset).setIdentity();
    J.block<3, 3>(0, kRotationOffset) = -R * SO3d::Hat(term.point_radar);
    const double weight = loss.Add(e.dot(S * e));
    const Eigen::Matrix<double, 6, 3> JtS = J.transpose() * S;
    A.noalias() += weight * JtS * J;
    scores.push_back({term.gaussian, weight * JtS * e});
  }
  std::sort(scores.begin(), scores.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  Eigen::Matrix<double, 6, 6> B = Eigen::Matrix<double, 6, 6>::Zero();
  std::size_t clusters = 0;
  for (std::size_t k = 0; k < scores.size();) {
    Vector6d u = Vector6d::Zero();
    const std::uint32_t gaussian = scores[k].first;
    for (; k < scores.size() && scores[k].first == gaussian; ++k) u += scores[k].second;
    B.noalias() += u * u.transpose();
    ++clusters;
  }
  constexpr std::size_t kMinClusters = 7;  // one more than the pose's dimensions
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> factor(A);
  if (clusters < kMinClusters || factor.info() != Eigen::Success || !(factor.vectorD().minCoeff() > 0.0)) {
    return Eigen::Matrix<double, 6, 6>::Zero();
  }
  const Eigen::Matrix<double, 6, 6> A_inverse = factor.solve(Eigen::Matrix<double, 6, 6>::Identity());
  const Eigen::Matrix<double, 6, 6> covariance = double(clusters) / double(clusters - 1) * A_inverse * B * A_inverse;
  return 0.5 * (covariance + covariance.transpose());
}

}  // namespace radargauss
