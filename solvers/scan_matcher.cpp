// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/scan_matcher.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "radargauss/conventions.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/names.hpp"
#include "radargauss/solvers/normal_equations.hpp"

namespace radargauss {

void ValidateOptions(const ScanMatchingOptions& o) {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(what);
  };
  require(o.w_rcs >= 0.0 && o.w_rcs <= 1.0, "w_rcs must be in [0, 1]");
  require(o.geometric_loss.scale > 0.0 && o.rcs_loss.scale > 0.0, "loss scales must be > 0");
  require(o.gate > 0.0, "association gate must be > 0");
  require(o.max_iterations >= 1 && o.coarse_iterations >= 1, "iteration limits must be >= 1");
  require(o.coarse_voxel_per_sigma >= 0.0 && std::isfinite(o.coarse_voxel_per_sigma),
          "coarse voxel per sigma must be >= 0 and finite");
  require(o.translation_tolerance > 0.0 && o.rotation_tolerance > 0.0 && o.coarse_translation_tolerance > 0.0 &&
              o.coarse_rotation_tolerance > 0.0,
          "tolerances must be > 0");
  require(o.reassociation_translation >= 0.0 && o.reassociation_rotation >= 0.0,
          "re-association thresholds must be >= 0");
}

std::vector<int> AssociateScan(const RadarScan& scan, const GaussianIndex& index, const SE3d& pose, double gate,
                               std::vector<double>* mahalanobis_sq) {
  const Eigen::Matrix3d R = pose.rotation().Matrix();
  const std::size_t n = scan.points.size();
  std::vector<Eigen::Vector3d> world(n);
  for (std::size_t k = 0; k < n; ++k) world[k] = R * scan.points[k].position + pose.translation();
  std::vector<int> associations(n);
  if (mahalanobis_sq) mahalanobis_sq->assign(n, 0.0);
  index.AssociateAll(world.data(), n, gate * gate, associations.data(),
                     mahalanobis_sq ? mahalanobis_sq->data() : nullptr);
  return associations;
}

Correspondences FindCorrespondences(const RadarScan& scan, const MatchingMap& map, std::size_t level,
                                    const SE3d& pose, double gate, bool with_rcs) {
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
  if (with_rcs) AddRcsTerms(scan, map, out);
  return out;
}

void AddRcsTerms(const RadarScan& scan, const MatchingMap& map, Correspondences& c) {
  c.rcs.clear();
  if (!scan.has_rcs) return;
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
    c.rcs.push_back(term);
  }
}

double EvaluateCost(const Correspondences& c, const SE3d& pose, const ScanMatchingOptions& options) {
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
  if (options.velocity && options.velocity->weight > 0.0) {
    f += options.velocity->weight * options.velocity->Residual(pose.translation()).squaredNorm();
  }
  if (options.rotation && options.rotation->weight > 0.0) {
    f += options.rotation->weight * options.rotation->Residual(pose.rotation()).squaredNorm();
  }
  return f;
}

bool CheckCorrespondences(const RadarScan& scan, const Correspondences& c,
                          const ScanMatchingOptions& options, std::string& reason) {
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
  const std::size_t residuals = (options.w_rcs < 1.0 ? 3 * c.geometric.size() : 0) +
                                (options.w_rcs > 0.0 ? c.rcs.size() : 0);
  const std::size_t freedom = options.w_rcs < 1.0 || options.rcs_translation == RcsTranslation::kFull ? 6 : 3;
  if (residuals < freedom) {
    reason = "too few residuals (" + std::to_string(residuals) + ") for " + std::to_string(freedom) +
             " degrees of freedom";
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

namespace {

// The points a coarse level matches, from the scan's `positions`: the
// centroids of their voxels of side `voxel` (0: the positions themselves),
// then at most `max_points` of them, evenly strided (0: all).
RadarScan CoarseScan(const std::vector<Eigen::Vector3d>& positions, double voxel, std::size_t max_points) {
  const std::vector<Eigen::Vector3d> centroids =
      voxel > 0.0 ? VoxelDownsample(positions, voxel, VoxelOrder::kFirstPoint) : std::vector<Eigen::Vector3d>();
  const std::vector<Eigen::Vector3d>& source = voxel > 0.0 ? centroids : positions;
  const std::size_t n = source.size();
  const std::size_t count = max_points > 0 ? std::min(max_points, n) : n;
  RadarScan coarse;
  coarse.points.resize(count);
  for (std::size_t k = 0; k < count; ++k) coarse.points[k].position = source[k * n / count];
  return coarse;
}

// The end of a match: the final association (the last one, when it was made
// on the exact map within the re-association thresholds of the final pose, or
// when not re-associating; otherwise a new one at the final pose), N_geo,
// N_rcs, the cost of eq. 2 (the one a step recorded at the final pose on that
// association, if any) and the information matrix.
void FinishResult(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                  const ScanMatchingOptions& options, const Correspondences& c, const EvaluatedCost& evaluated,
                  ScanMatchingResult& result) {
  if (result.iterations == 0) {
    result.pose = initial;
    return;
  }
  const bool last_is_final = KeepsAssociation(c.index == &map.index(), c.pose, result.pose, options);
  const Correspondences final_c = last_is_final ? c
                                                : FindCorrespondences(scan, map, map.levels() - 1, result.pose,
                                                                      options.gate, options.w_rcs > 0.0);
  result.n_geo = final_c.geometric.size();
  result.n_rcs = final_c.rcs.size();
  // On the exact map the steps' options are these (w_rcs is the requested w there).
  const bool known =
      last_is_final && c.index == &map.index() && evaluated.known && SamePose(evaluated.pose, result.pose);
  result.final_cost = known ? evaluated.cost : EvaluateCost(final_c, result.pose, options);
  result.information = InformationMatrix(final_c, result.pose, options);
  if (options.velocity && options.velocity->weight > 0.0) {
    const Eigen::Matrix3d J = options.velocity->Jacobian();
    result.velocity_information.block<3, 3>(kTranslationOffset, kTranslationOffset) =
        options.velocity->weight * J.transpose() * J;
  }
  if (options.rotation && options.rotation->weight > 0.0) {
    const Eigen::Matrix3d J = options.rotation->Jacobian(result.pose.rotation());
    result.rotation_information.block<3, 3>(kRotationOffset, kRotationOffset) =
        options.rotation->weight * J.transpose() * J;
  }
}

}  // namespace

ScanMatchingResult RunCoarseToFine(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                                   const ScanMatchingOptions& options, const SolverStep& step) {
  const auto start = std::chrono::steady_clock::now();
  ScanMatchingResult result;
  result.pose = initial;
  const double w = options.w_rcs;
  Correspondences c;
  EvaluatedCost evaluated;  // on c
  bool failed = false;
  // The coarse levels' points (CoarseScan): voxel centroids, made per level
  // from the scan's positions, or the scan's own points, strided once when
  // there are more than coarse_points.
  const bool voxels = options.coarse_voxel_per_sigma > 0.0;
  const bool reduce = w < 1.0 && (voxels || (options.coarse_points > 0 && scan.points.size() > options.coarse_points));
  std::vector<Eigen::Vector3d> positions;
  if (reduce) {
    positions.reserve(scan.points.size());
    for (const RadarPoint& point : scan.points) positions.push_back(point.position);
  }
  RadarScan coarse_scan;
  // The stages: the coarse levels, the exact map with the geometric term
  // alone (geometric_first, when re-associating), the exact map with eq. 2;
  // with w = 1 the last alone.
  const bool geometric_first = options.geometric_first && options.reassociate && w > 0.0 && w < 1.0;
  const std::size_t stages = map.levels() + (geometric_first ? 1 : 0);
  for (std::size_t stage = w < 1.0 ? 0 : stages - 1; stage < stages && !failed; ++stage) {
    const std::size_t level = std::min(stage, map.levels() - 1);
    const bool finest = level + 1 == map.levels();
    const bool full_cost = stage + 1 == stages;  // eq. 2 with the requested w
    ScanMatchingOptions level_options = options;
    level_options.w_rcs = full_cost ? w : 0.0;
    const int max_iterations = full_cost ? options.max_iterations : options.coarse_iterations;
    const bool with_rcs = level_options.w_rcs > 0.0;
    result.converged = false;
    if (!finest && reduce && (voxels || level == 0)) {  // strided points: the same on every level
      coarse_scan = CoarseScan(positions, options.coarse_voxel_per_sigma * map.sigma(level), options.coarse_points);
    }
    const RadarScan& level_scan = finest || !reduce ? scan : coarse_scan;
    const double gate = finest ? options.gate : map.coarse_gate();
    if (full_cost && geometric_first && KeepsAssociation(true, c.pose, result.pose, options)) {
      AddRcsTerms(scan, map, c);  // eq. 2 on the geometric stage's last association (same level)
    } else {
      c = FindCorrespondences(level_scan, map, level, result.pose, gate, with_rcs);
    }
    evaluated.known = false;
    for (int iteration = 1; iteration <= max_iterations; ++iteration) {
      if (iteration > 1 && !KeepsAssociation(finest, c.pose, result.pose, options)) {
        c = FindCorrespondences(level_scan, map, level, result.pose, gate, with_rcs);
        evaluated.known = false;
      }
      if (!CheckCorrespondences(level_scan, c, level_options, result.reason)) {
        failed = true;
        break;
      }
      ++result.iterations;
      const StepOutcome outcome =
          step({c, level_options, finest, full_cost,
                full_cost ? options.translation_tolerance : options.coarse_translation_tolerance,
                full_cost ? options.rotation_tolerance : options.coarse_rotation_tolerance,
                iteration == max_iterations, &evaluated},
               result);
      if (outcome == StepOutcome::kFailed) failed = true;
      if (outcome != StepOutcome::kContinue) {
        result.converged = outcome == StepOutcome::kConverged;
        break;
      }
    }
  }
  if (failed) result.converged = false;
  if (!result.converged && result.reason.empty()) result.reason = "iteration limit reached";
  FinishResult(scan, map, initial, options, c, evaluated, result);
  result.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace radargauss
