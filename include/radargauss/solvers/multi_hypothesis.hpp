// SPDX-License-Identifier: BSD-3-Clause
// Multi-hypothesis scan matching (the RA-L work): several starts around the
// initial pose (x/y and yaw perturbations), each refined by an inner solver;
// the best score wins. Score (lower is better): the mean over all scan points
// of min(Mahalanobis^2, tau^2) at the refined pose, so a start that leaves
// points unassociated pays for them; a non-converged refinement only wins
// when none converged.
#pragma once

#include <memory>
#include <vector>

#include "radargauss/solvers/scan_matcher.hpp"
#include "radargauss/solvers/solver_options.hpp"

namespace radargauss {

// Start offsets (dx, dy, dyaw) in the radar frame: the initial pose, +/-x,
// +/-y, +/-yaw, the four xy diagonals, and +/-yaw at +x.
std::vector<Eigen::Vector3d> HypothesisOffsets(const MultiHypothesisOptions& options);

class MultiHypothesisSolver final : public ScanMatcher {
 public:
  MultiHypothesisSolver(std::shared_ptr<const ScanMatcher> inner, const ScanMatchingOptions& options,
                        const MultiHypothesisOptions& hypotheses = {});
  std::string Name() const override;
  using ScanMatcher::Match;
  ScanMatchingResult Match(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                           const ScanPriors& priors) const override;

 private:
  std::shared_ptr<const ScanMatcher> inner_;
  ScanMatchingOptions options_;
  MultiHypothesisOptions hypotheses_;
};

}  // namespace radargauss
