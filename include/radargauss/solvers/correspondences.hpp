// SPDX-License-Identifier: BSD-3-Clause
// What every single-scan solver shares (docs/design/residuals.md, "Association" and
// "The combined cost"): the correspondences of a scan with a level of the
// MatchingMap, how they are made and kept, and eq. 2 on them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "radargauss/lie/se3.hpp"
#include "radargauss/map/matching_map.hpp"
#include "radargauss/residuals/priors.hpp"
#include "radargauss/residuals/rcs_residual.hpp"
#include "radargauss/solvers/scan_matcher.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

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
// (and the scan has RCS), made as `rcs_terms` says.
Correspondences FindCorrespondences(const RadarScan& scan, const MatchingMap& map, std::size_t level, const SE3d& pose,
                                    double gate, bool with_rcs, const RcsTermOptions& rcs_terms = {});

// Replaces the RCS terms of `correspondences` (made from `scan`) by those of
// their geometric pairs, at the pose they were made at: what
// FindCorrespondences gives with_rcs, without associating again (when the
// scan has RCS).
void AddRcsTerms(const RadarScan& scan, const MatchingMap& map, Correspondences& correspondences,
                 const RcsTermOptions& rcs_terms = {});

// f of eq. 2 for fixed correspondences at `pose`, plus the terms of
// `priors`. RCS residuals take the translation of the correspondences when
// rotation-only.
double EvaluateCost(const Correspondences& correspondences, const SE3d& pose, const ScanMatchingOptions& options,
                    const ScanPriors& priors);

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
  return a.translation() == b.translation() && a.rotation().quaternion().coeffs() == b.rotation().quaternion().coeffs();
}

}  // namespace radargauss
