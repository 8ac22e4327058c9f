// SPDX-License-Identifier: BSD-3-Clause
// Scan matching against a Gaussian-RCS map (paper section III-B, docs/design/residuals.md,
// "Scan matching"): the options, the result and the interface every solver
// implements (the pieces they share: solvers/correspondences.hpp).
//
// The cost (eq. 2):
//   f = (1 - w)/N_geo * sum rho_geo(||r_geo||^2) + w/N_rcs * sum rho_rcs(r_rcs^2),
// N counting the residuals that contributed; RCS residuals only for points
// whose normalised RCS is in [-1, 1] and whose Gaussian has a model.
// Pose: rotation quaternion + translation; updates [dt (world); dphi (radar)].
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/lie/se3.hpp"
#include "radargauss/map/matching_map.hpp"
#include "radargauss/core/options.hpp"
#include "radargauss/residuals/loss.hpp"
#include "radargauss/residuals/priors.hpp"
#include "radargauss/residuals/rcs_likelihood.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

// How the RCS term treats translation: the paper's rotation-only, or full.
enum class RcsTranslation { kRotationOnly, kFull };
std::string ToString(RcsTranslation mode);                         // "rotation-only", "full"
RcsTranslation RcsTranslationFromString(const std::string& name);  // throws std::invalid_argument
std::vector<std::string> RcsTranslationNames();
// Which Jacobians a solver uses: closed form, or Jets through the functors.
enum class JacobianMode { kAnalytic, kAutoDiff };
std::string ToString(JacobianMode mode);                       // "analytic", "autodiff"
JacobianMode JacobianModeFromString(const std::string& name);  // throws std::invalid_argument
std::vector<std::string> JacobianModeNames();

struct ScanMatchingOptions {
  double w_rcs = 0.0;  // eq. 2's w, in [0, 1]
  LossConfig geometric_loss{LossType::kTrivial, 1.0};
  LossConfig rcs_loss{LossType::kCauchy, 1.0};  // the paper: Cauchy
  RcsTermOptions rcs_terms;                     // the RCS likelihood and confidence
  RcsTranslation rcs_translation = RcsTranslation::kRotationOnly;
  JacobianMode jacobians = JacobianMode::kAnalytic;
  double gate = 3.0;           // tau: association gate (Mahalanobis distance)
  int max_iterations = 30;     // outer iterations (association + update) on the exact map
  int coarse_iterations = 15;  // outer iterations on each coarse level of the MatchingMap
  // Coarse levels match the centroids of the scan's voxels of side
  // coarse_voxel_per_sigma * sigma_k (0: the points), then at most
  // coarse_points of them, evenly strided (0: all).
  double coarse_voxel_per_sigma = 2.0;
  std::size_t coarse_points = 0;
  // With 0 < w < 1: on the exact map the geometric term alone first, then
  // eq. 2 from there, so the RCS terms enter the last iterations only (the
  // same optimum); false: eq. 2 throughout.
  bool geometric_first = true;
  bool reassociate = true;  // false: associate once at the initial pose
  // Lazy re-association on the exact map: again only once the pose has moved
  // more than this since the last association (docs/design/residuals.md,
  // "Association"); 0 re-associates after every step.
  double reassociation_translation = 0.01;     // m
  double reassociation_rotation = 0.002;       // rad
  double translation_tolerance = 1e-3;         // m: stop when the update is smaller ...
  double rotation_tolerance = 1e-4;            // rad ... in both parts, on the exact map
  double coarse_translation_tolerance = 1e-2;  // m: the same on coarse levels, which
  double coarse_rotation_tolerance = 1e-3;     // rad only steer into the exact map's basin
  // Also state ScanMatchingResult::covariance (MatchCovariance): one more
  // pass over the final residuals, which a match that only needs its pose skips.
  bool pose_covariance = false;
};

// Its options (options.hpp); ValidateOptions throws std::invalid_argument naming the bad one.
const OptionTable<ScanMatchingOptions>& ScanMatchingOptionTable();
void ValidateOptions(const ScanMatchingOptions& options);

struct ScanMatchingResult {
  SE3d pose;  // T_world_radar at the end
  int iterations = 0;
  double final_cost = 0.0;  // f of eq. 2 at the final pose and association
  std::size_t n_geo = 0;
  std::size_t n_rcs = 0;
  bool converged = false;
  std::string reason;  // why it did not converge; empty when it did
  double time_ms = 0.0;
  // The Gauss-Newton matrix of eq. 2's f at the final pose and association,
  // over the solvers' tangent [dt (world); dphi (radar)] (conventions.hpp):
  // (1-w)/N_geo H_geo + w/N_rcs H_rcs with the losses' IRLS weights, the RCS
  // part on the rotation block only when rotation-only. Zero when no match
  // was made. Multiply by N_geo (w = 0) for the information of the pose in
  // the Gaussians' units; docs/design/solvers.md, "The information matrix".
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  // The pose's covariance over the same tangent from the geometric
  // residuals' own spread (MatchCovariance, normal_equations.hpp): what the
  // match knows of the pose against this map. Zero unless asked for
  // (ScanMatchingOptions::pose_covariance), no match was made or too few
  // Gaussians were matched.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  // The velocity prior's Gauss-Newton matrix, weight J^T J on the translation
  // block (zero without the prior), kept apart from eq. 2's.
  Eigen::Matrix<double, 6, 6> velocity_information = Eigen::Matrix<double, 6, 6>::Zero();
  // The rotation prior's, weight J^T J on the rotation block at the final pose.
  Eigen::Matrix<double, 6, 6> rotation_information = Eigen::Matrix<double, 6, 6>::Zero();
};

// The interface of every solver. A matcher holds its options only; the
// scan's own terms (odometry's velocity and rotation priors) are arguments,
// so one matcher serves every scan of a map.
class ScanMatcher {
 public:
  virtual ~ScanMatcher() = default;
  virtual std::string Name() const = 0;
  // Minimises eq. 2 plus the terms of `priors` for `scan` against `map` from
  // `initial` (T_world_radar).
  virtual ScanMatchingResult Match(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                                   const ScanPriors& priors) const = 0;
  // Eq. 2 alone.
  ScanMatchingResult Match(const RadarScan& scan, const MatchingMap& map, const SE3d& initial) const {
    return Match(scan, map, initial, ScanPriors{});
  }
};

}  // namespace radargauss
