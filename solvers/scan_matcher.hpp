// SPDX-License-Identifier: BSD-3-Clause
// Scan matching against a Gaussian-RCS map (paper section III-B, docs/design.md,
// "Scan matching"): the options, the result and the interface every solver
// implements, and the pieces they share (association, the cost of eq. 2).
//
// The cost (eq. 2):
//   f = (1 - w)/N_geo * sum rho_geo(||r_geo||^2) + w/N_rcs * sum rho_rcs(r_rcs^2),
// N counting the residuals that contributed; RCS residuals only for points
// whose normalised RCS is in [-1, 1] and whose Gaussian has a model.
// Pose: rotation quaternion + translation; updates [dt (world); dphi (radar)].
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "radargauss/lie/se3.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/types.hpp"
#include "radargauss/residuals/loss.hpp"
#include "radargauss/residuals/rcs_residual.hpp"
#include "radargauss/residuals/rotation_residual.hpp"
#include "radargauss/residuals/velocity_residual.hpp"
#include "radargauss/solvers/matching_map.hpp"

namespace radargauss {

// How the RCS term treats translation: the paper's rotation-only, or full.
enum class RcsTranslation { kRotationOnly, kFull };
// Which Jacobians a solver uses: closed form, or Jets through the functors.
enum class JacobianMode { kAnalytic, kAutoDiff };

struct ScanMatchingOptions {
  double w_rcs = 0.0;  // eq. 2's w, in [0, 1]
  LossConfig geometric_loss{LossType::kTrivial, 1.0};
  LossConfig rcs_loss{LossType::kCauchy, 1.0};  // the paper: Cauchy
  RcsTranslation rcs_translation = RcsTranslation::kRotationOnly;
  JacobianMode jacobians = JacobianMode::kAnalytic;
  double gate = 3.0;          // tau: association gate (Mahalanobis distance)
  int max_iterations = 30;    // outer iterations (association + update) on the exact map
  int coarse_iterations = 15; // outer iterations on each coarse level of the MatchingMap
  // Coarse levels match the centroids of the scan's voxels of side
  // coarse_voxel_per_sigma * sigma_k (0: the points), then at most
  // coarse_points of them, evenly strided (0: all).
  double coarse_voxel_per_sigma = 2.0;
  std::size_t coarse_points = 0;
  // With 0 < w < 1: on the exact map the geometric term alone first, then
  // eq. 2 from there, so the RCS terms enter the last iterations only (the
  // same optimum); false: eq. 2 throughout.
  bool geometric_first = true;
  bool reassociate = true;    // false: associate once at the initial pose
  // Lazy re-association on the exact map: again only once the pose has moved
  // more than this since the last association (docs/design.md,
  // "Association"); 0 re-associates after every step.
  double reassociation_translation = 0.01;  // m
  double reassociation_rotation = 0.002;    // rad
  // Odometry's Doppler velocity term, added to eq. 2 as weight * |r_v|^2 on
  // every level (docs/design.md, "The velocity term"); none: eq. 2 alone.
  std::optional<VelocityPrior> velocity;
  // Odometry's rotation term, weight * |r_w|^2 on every level (docs/design.md,
  // "The rotation term"); none: no prior on the rotation.
  std::optional<RotationPrior> rotation;
  double translation_tolerance = 1e-3;         // m: stop when the update is smaller ...
  double rotation_tolerance = 1e-4;            // rad ... in both parts, on the exact map
  double coarse_translation_tolerance = 1e-2;  // m: the same on coarse levels, which
  double coarse_rotation_tolerance = 1e-3;     // rad only steer into the exact map's basin
};

// Throws std::invalid_argument naming the bad option.
void ValidateOptions(const ScanMatchingOptions& options);

struct ScanMatchingResult {
  SE3d pose;                // T_world_radar at the end
  int iterations = 0;
  double final_cost = 0.0;  // f of eq. 2 at the final pose and association
  std::size_t n_geo = 0;
  std::size_t n_rcs = 0;
  bool converged = false;
  std::string reason;       // why it did not converge; empty when it did
  double time_ms = 0.0;
  // The Gauss-Newton matrix of eq. 2's f at the final pose and association,
  // over the solvers' tangent [dt (world); dphi (radar)] (conventions.hpp):
  // (1-w)/N_geo H_geo + w/N_rcs H_rcs with the losses' IRLS weights, the RCS
  // part on the rotation block only when rotation-only. Zero when no match
  // was made. Multiply by N_geo (w = 0) for the information of the pose in
  // the Gaussians' units; docs/design.md, "The information matrix".
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  // The velocity term's Gauss-Newton matrix, weight J^T J on the translation
  // block (zero without the term), kept apart from eq. 2's.
  Eigen::Matrix<double, 6, 6> velocity_information = Eigen::Matrix<double, 6, 6>::Zero();
  // The rotation term's, weight J^T J on the rotation block at the final pose.
  Eigen::Matrix<double, 6, 6> rotation_information = Eigen::Matrix<double, 6, 6>::Zero();
};

struct GeometricTerm {
  Eigen::Vector3d point_radar;
  std::uint32_t gaussian = 0;
  std::uint32_t point = 0;  // index in the scan it was associated from
};

struct Correspondences {
  const GaussianIndex* index = nullptr;  // the level they were made with
  std::vector<GeometricTerm> geometric;
  std::vector<RcsTerm> rcs;
  SE3d pose;  // the pose they were made at
};

// The Gaussian of `index` each point of the scan goes to at `pose` (-1:
// none within the gate), batched (GaussianIndex::AssociateAll); writes each
// associated point's Mahalanobis^2 too when asked.
std::vector<int> AssociateScan(const RadarScan& scan, const GaussianIndex& index, const SE3d& pose, double gate,
                               std::vector<double>* mahalanobis_sq = nullptr);

// Associates every point at `pose` with the Gaussians of `level`
// (smallest Mahalanobis^2 within the gate); RCS terms too when `with_rcs`
// (and the scan has RCS).
Correspondences FindCorrespondences(const RadarScan& scan, const MatchingMap& map, std::size_t level,
                                    const SE3d& pose, double gate, bool with_rcs);

// Replaces the RCS terms of `correspondences` (made from `scan`) by those of
// their geometric pairs, at the pose they were made at: what
// FindCorrespondences gives with_rcs, without associating again (when the
// scan has RCS).
void AddRcsTerms(const RadarScan& scan, const MatchingMap& map, Correspondences& correspondences);

// f of eq. 2 for fixed correspondences at `pose`. RCS residuals take the
// translation of the correspondences when rotation-only.
double EvaluateCost(const Correspondences& correspondences, const SE3d& pose,
                    const ScanMatchingOptions& options);

// Whether the outer loop keeps correspondences made at `associated_at` once
// the pose is `pose`: always when not re-associating; on the exact map (the
// lazy rule, see ScanMatchingOptions) until the pose has moved past the
// re-association thresholds; never on a coarse level.
bool KeepsAssociation(bool exact_level, const SE3d& associated_at, const SE3d& pose,
                      const ScanMatchingOptions& options);

// Checks the inputs every solver shares; false with a reason for an empty
// scan or a term that has no residuals although its weight is not zero.
bool CheckCorrespondences(const RadarScan& scan, const Correspondences& correspondences,
                          const ScanMatchingOptions& options, std::string& reason);

// Whether two poses are bit for bit the same (the same association, the
// same evaluated cost).
inline bool SamePose(const SE3d& a, const SE3d& b) {
  return a.translation() == b.translation() &&
         a.rotation().quaternion().coeffs() == b.rotation().quaternion().coeffs();
}

// The cost of eq. 2 on the current correspondences at a pose, when a step
// evaluated it there: the loop reuses it as the final cost instead of
// evaluating it again.
struct EvaluatedCost {
  bool known = false;
  SE3d pose;
  double cost = 0.0;
};

// What a solver's step sees of one iteration of the outer loop that every
// single-scan solver shares (RunCoarseToFine; docs/design.md, "Coarse to fine").
struct LevelStep {
  const Correspondences& correspondences;
  const ScanMatchingOptions& options;  // with this level's w_rcs
  bool finest = false;                 // on the exact map
  bool full_cost = false;              // eq. 2 with the match's w: its last stage (else one that steers)
  double translation_tolerance = 0.0;  // m: this level's step tolerances
  double rotation_tolerance = 0.0;     // rad
  bool last_iteration = false;         // the level's iteration limit is reached with this step
  EvaluatedCost* evaluated = nullptr;  // a step may record EvaluateCost at the pose it leaves
  // Whether a step (translation norm, rotation angle) ends the level.
  bool SmallStep(double translation, double rotation) const {
    return translation < translation_tolerance && rotation < rotation_tolerance;
  }
};
enum class StepOutcome { kContinue, kConverged, kFailed };
using SolverStep = std::function<StepOutcome(const LevelStep&, ScanMatchingResult&)>;

// Matches level by level, associating as docs/design.md, "Association" says,
// and lets `step` move result.pose; then fills in the final counts, eq. 2 and
// the information matrix.
ScanMatchingResult RunCoarseToFine(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                                   const ScanMatchingOptions& options, const SolverStep& step);

class ScanMatcher {
 public:
  virtual ~ScanMatcher() = default;
  virtual std::string Name() const = 0;
  virtual ScanMatchingResult Match(const RadarScan& scan, const MatchingMap& map,
                                   const SE3d& initial) const = 0;
};

}  // namespace radargauss
