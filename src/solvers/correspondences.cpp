// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/correspondences.hpp"

#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "radargauss/residuals/robust_loss.hpp"

namespace radargauss {

namespace {

// Points a task associates: a block amortises the task and the prefetching
// of AssociateAll, and a scan of a few thousand points still splits.
constexpr std::size_t kAssociationBlock = 256;

}  // namespace

std::vector<int> AssociateScan(const RadarScan& scan, const GaussianIndex& index, const SE3d& pose, double gate,
                               std::vector<double>* mahalanobis_sq) {
  const Eigen::Matrix3d R = pose.rotation().Matrix();
  const std::size_t n = scan.points.size();
  std::vector<Eigen::Vector3d> world(n);
  std::vector<int> associations(n);
  if (mahalanobis_sq) mahalanobis_sq->assign(n, 0.0);
  // Each point's answer is its own: blocks of points run side by side with
  // the same answers as one pass.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kAssociationBlock), [&](const auto& range) {
    for (std::size_t k = range.begin(); k < range.end(); ++k) {
      world[k] = R * scan.points[k].position + pose.translation();
    }
    index.AssociateAll(world.data() + range.begin(), range.size(), gate * gate, associations.data() + range.begin(),
                       mahalanobis_sq ? mahalanobis_sq->data() + range.begin() : nullptr);
  });
  return associations;
}

Correspondences FindCorrespondences(const RadarScan& scan, const MatchingMap& map, std::size_t level, const SE3d& pose,
                                    double gate, bool with_rcs, const RcsTermOptions& rcs_terms) {
  Correspondences out;
  out.index = &map.level(level);
  out.pose = pose;
  out.geometric.reserve(scan.points.size());
  const std::vector<int> associations = AssociateScan(scan, *out.index, pose, gate);
  for (std::size_t k = 0; k < associations.size(); ++k) {
    if (associations[k] >= 0) {
      out.geometric.push_back({scan.points[k].position, std::uint32_t(associations[k]), std::uint32_t(k)});
    }
  }
  if (with_rcs) AddRcsTerms(scan, map, out, rcs_terms);
  return out;
}

void AddRcsTerms(const RadarScan& scan, const MatchingMap& map, Correspondences& c, const RcsTermOptions& rcs_terms) {
  c.rcs.clear();
  if (!scan.has_rcs) return;
  const double shape = SwerlingShape(rcs_terms.likelihood);
  const double expected_spread = ExpectedSpreadDb(rcs_terms);
  c.rcs.reserve(c.geometric.size());
  const Eigen::Matrix3d Rt = c.pose.rotation().Matrix().transpose();
  const std::vector<Gaussian>& gaussians = map.map().gaussians;
  const std::size_t n = c.geometric.size();
  constexpr std::size_t kAhead = 8;  // RCS terms read the Gaussian's model: fetch it early
  for (std::size_t k = 0; k < n; ++k) {
    if (k + kAhead < n) __builtin_prefetch(&gaussians[c.geometric[k + kAhead].gaussian].rcs);
    const GeometricTerm& pair = c.geometric[k];
    const RadarPoint& point = scan.points[pair.point];
    const Gaussian& gaussian = gaussians[pair.gaussian];
    if (!gaussian.rcs.valid()) continue;
    const double y = gaussian.rcs.Normalise(point.rcs);
    if (!(std::abs(y) <= 1.0)) continue;  // RCS outlier: no residual (eq. 2)
    const Eigen::Vector3d mean_radar = Rt * (gaussian.mean - c.pose.translation());
    const Eigen::Vector3d u = IncidenceVector(map.map().incidence, point.position, mean_radar);
    if (u.squaredNorm() < 1e-12) continue;  // no incidence direction
    RcsTerm term;
    term.point_radar = point.position;
    term.mean = gaussian.mean;
    term.measurement = y;
    term.degree = gaussian.rcs.degree;
    term.coefficients = gaussian.rcs.coefficients;
    term.incidence = map.map().incidence;
    term.facing = FacingSign(u);
    term.gaussian = pair.gaussian;
    if (shape > 0.0) {  // z = ln(sigma / mean) from the decibel residual (rcs_likelihood.hpp)
      term.shape = shape;
      term.log_scale = kNepersPerDecibel * gaussian.rcs.scale;
      term.log_offset = -kNepersPerDecibel * gaussian.rcs.mean_offset_db;
    }
    if (rcs_terms.confidence) {
      const double confidence =
          RcsConfidence(gaussian.rcs.spread_db, gaussian.rcs.degree, gaussian.rcs.inliers, expected_spread);
      if (!(confidence > 0.0)) continue;  // says nothing: no residual
      term.weight = std::sqrt(confidence);
    }
    c.rcs.push_back(term);
  }
}

double EvaluateCost(const Correspondences& c, const SE3d& pose, const ScanMatchingOptions& options,
                    const ScanPriors& priors) {
  LossSum geometric(options.geometric_loss), rcs(options.rcs_loss);
  // One rotation matrix for all terms (the functors rotate by the quaternion per term).
  const Eigen::Matrix3d R = pose.rotation().Matrix();
  const Eigen::Matrix3d Rt = R.transpose();
  for (const GeometricTerm& term : c.geometric) {
    const Eigen::Vector3d e = R * term.point_radar + pose.translation() - c.index->Mean(term.gaussian);
    geometric.Add(c.index->MahalanobisSq(term.gaussian, e));  // ||L^T e||^2
  }
  const Eigen::Vector3d rcs_translation =
      options.rcs_translation == RcsTranslation::kRotationOnly ? c.pose.translation() : pose.translation();
  for (const RcsTerm& term : c.rcs) {
    const double r = RcsResidualAt<double>(term, Rt * (term.mean - rcs_translation), term.coefficients.data());
    rcs.Add(r * r);
  }
  double f = 0.0;
  if (options.w_rcs < 1.0 && !c.geometric.empty()) f += (1.0 - options.w_rcs) / c.geometric.size() * geometric.Sum();
  if (options.w_rcs > 0.0 && !c.rcs.empty()) f += options.w_rcs / c.rcs.size() * rcs.Sum();
  if (priors.velocity && priors.velocity->weight > 0.0) {
    f += priors.velocity->weight * priors.velocity->Residual(pose.translation()).squaredNorm();
  }
  if (priors.rotation && priors.rotation->weight > 0.0) {
    f += priors.rotation->weight * priors.rotation->Residual(pose.rotation()).squaredNorm();
  }
  return f;
}

bool CheckCorrespondences(const RadarScan& scan, const Correspondences& c, const ScanMatchingOptions& options,
                          std::string& reason) {
  if (scan.points.empty()) {
    reason = "empty scan";
    return false;
  }
  if (options.w_rcs < 1.0 && c.geometric.empty()) {
    reason = "no point associated to the map";
    return false;
  }
  if (options.w_rcs > 0.0 && c.rcs.empty()) {
    reason = "no RCS residuals (no RCS in the scan, no models, or all RCS outliers)";
    return false;
  }
  // Enough residuals for the degrees of freedom the weighted terms drive.
  const std::size_t residuals =
      (options.w_rcs < 1.0 ? 3 * c.geometric.size() : 0) + (options.w_rcs > 0.0 ? c.rcs.size() : 0);
  const std::size_t freedom = options.w_rcs < 1.0 || options.rcs_translation == RcsTranslation::kFull ? 6 : 3;
  if (residuals < freedom) {
    reason =
        "too few residuals (" + std::to_string(residuals) + ") for " + std::to_string(freedom) + " degrees of freedom";
    return false;
  }
  return true;
}

bool KeepsAssociation(bool exact_level, const SE3d& associated_at, const SE3d& pose,
                      const ScanMatchingOptions& options) {
  if (!options.reassociate) return true;
  return exact_level &&
         (pose.translation() - associated_at.translation()).norm() <= options.reassociation_translation &&
         (associated_at.rotation().Inverse() * pose.rotation()).Log().norm() <= options.reassociation_rotation;
}

}  // namespace radargauss
