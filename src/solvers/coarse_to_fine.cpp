// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/coarse_to_fine.hpp"

#include <algorithm>

#include "radargauss/core/conventions.hpp"
#include "radargauss/solvers/normal_equations.hpp"
#include "radargauss/core/voxel_grid.hpp"

namespace radargauss {

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

}  // namespace

CoarseToFine::CoarseToFine(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                           const ScanMatchingOptions& options, const ScanPriors& priors)
    : scan_(scan), map_(map), initial_(initial), options_(options), priors_(priors) {
  result_.pose = initial;
  const double w = options.w_rcs;
  // The coarse levels' points (CoarseScan): voxel centroids, made per level
  // from the scan's positions, or the scan's own points, strided once when
  // there are more than coarse_points.
  const bool voxels = options.coarse_voxel_per_sigma > 0.0;
  reduce_ = w < 1.0 && (voxels || (options.coarse_points > 0 && scan.points.size() > options.coarse_points));
  if (reduce_) {
    positions_.reserve(scan.points.size());
    for (const RadarPoint& point : scan.points) positions_.push_back(point.position);
  }
  geometric_first_ = options.geometric_first && options.reassociate && w > 0.0 && w < 1.0;
  const std::size_t count = map.levels() + (geometric_first_ ? 1 : 0);
  for (std::size_t k = w < 1.0 ? 0 : count - 1; k < count; ++k) {
    Stage stage;
    stage.level = std::min(k, map.levels() - 1);
    stage.finest = stage.level + 1 == map.levels();
    stage.full_cost = k + 1 == count;
    stage.options = options;
    stage.options.w_rcs = stage.full_cost ? w : 0.0;
    stage.max_iterations = stage.full_cost ? options.max_iterations : options.coarse_iterations;
    stage.translation_tolerance =
        stage.full_cost ? options.translation_tolerance : options.coarse_translation_tolerance;
    stage.rotation_tolerance = stage.full_cost ? options.rotation_tolerance : options.coarse_rotation_tolerance;
    stages_.push_back(stage);
  }
}

void CoarseToFine::Begin(const Stage& stage) {
  const bool voxels = options_.coarse_voxel_per_sigma > 0.0;
  if (!stage.finest && reduce_ && (voxels || stage.level == 0)) {  // strided points: the same on every level
    coarse_scan_ =
        CoarseScan(positions_, options_.coarse_voxel_per_sigma * map_.sigma(stage.level), options_.coarse_points);
  }
  stage_scan_ = stage.finest || !reduce_ ? &scan_ : &coarse_scan_;
  gate_ = stage.finest ? options_.gate : map_.coarse_gate();
  if (stage.full_cost && geometric_first_ && KeepsAssociation(true, correspondences_.pose, result_.pose, options_)) {
    AddRcsTerms(scan_, map_, correspondences_,
                options_.rcs_terms);  // eq. 2 on the geometric stage's last association (same level)
  } else {
    correspondences_ = FindCorrespondences(*stage_scan_, map_, stage.level, result_.pose, gate_,
                                           stage.options.w_rcs > 0.0, options_.rcs_terms);
  }
  evaluated_.known = false;
}

bool CoarseToFine::Associate(const Stage& stage, int iteration) {
  if (iteration == 1) {
    Begin(stage);
  } else if (!KeepsAssociation(stage.finest, correspondences_.pose, result_.pose, options_)) {
    correspondences_ = FindCorrespondences(*stage_scan_, map_, stage.level, result_.pose, gate_,
                                           stage.options.w_rcs > 0.0, options_.rcs_terms);
    evaluated_.known = false;
  }
  if (!CheckCorrespondences(*stage_scan_, correspondences_, stage.options, result_.reason)) return false;
  ++result_.iterations;
  return true;
}

ScanMatchingResult CoarseToFine::Finish(bool converged) {
  ScanMatchingResult result = result_;
  result.converged = converged;
  if (!converged && result.reason.empty()) result.reason = "iteration limit reached";
  if (result.iterations == 0) {
    result.pose = initial_;
  } else {
    FinishCounts(result);
  }
  result.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
  return result;
}

void CoarseToFine::FinishCounts(ScanMatchingResult& result) const {
  const MatchingMap& map = map_;
  const ScanMatchingOptions& options = options_;
  const ScanPriors& priors = priors_;
  const Correspondences& c = correspondences_;
  const bool last_is_final = KeepsAssociation(c.index == &map.index(), c.pose, result.pose, options);
  const Correspondences final_c = last_is_final
                                      ? c
                                      : FindCorrespondences(scan_, map, map.levels() - 1, result.pose, options.gate,
                                                            options.w_rcs > 0.0, options.rcs_terms);
  result.n_geo = final_c.geometric.size();
  result.n_rcs = final_c.rcs.size();
  // On the exact map the steps' options are these (w_rcs is the requested w there).
  const bool known =
      last_is_final && c.index == &map.index() && evaluated_.known && SamePose(evaluated_.pose, result.pose);
  result.final_cost = known ? evaluated_.cost : EvaluateCost(final_c, result.pose, options, priors);
  result.information = InformationMatrix(final_c, result.pose, options);
  if (options.pose_covariance) result.covariance = MatchCovariance(final_c, result.pose, options);
  if (priors.velocity && priors.velocity->weight > 0.0) {
    const Eigen::Matrix3d J = priors.velocity->Jacobian();
    result.velocity_information.block<3, 3>(kTranslationOffset, kTranslationOffset) =
        priors.velocity->weight * J.transpose() * J;
  }
  if (priors.rotation && priors.rotation->weight > 0.0) {
    const Eigen::Matrix3d J = priors.rotation->Jacobian(result.pose.rotation());
    result.rotation_information.block<3, 3>(kRotationOffset, kRotationOffset) =
        priors.rotation->weight * J.transpose() * J;
  }
}

}  // namespace radargauss
