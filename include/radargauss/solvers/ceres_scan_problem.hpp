// SPDX-License-Identifier: BSD-3-Clause
// The ceres::Problem of a scan match (docs/design/solvers.md, "Ceres"): the pose
// blocks and the terms of the current association, with eq. 2's weights.
#pragma once

#include <ceres/problem.h>

#include <memory>

#include "radargauss/solvers/correspondences.hpp"
#include "radargauss/solvers/solver_options.hpp"

namespace radargauss {

// The ceres::Problem of one match, kept across associations: the pose blocks
// and the current association's terms, shared, square-root or one block per
// term (docs/design/solvers.md, "The residual blocks"), with eq. 2's weights.
class CeresScanProblem {
 public:
  static constexpr std::size_t kTermsPerBlock = 64;  // kShared

  // `rotation` (quaternion x y z w) and `translation` are the parameter
  // blocks; they must outlive the problem. `priors`: the scan's terms, in
  // every association. `threads`: square-root blocks per kind of term.
  CeresScanProblem(const ScanMatchingOptions& options, const ScanPriors& priors, double* rotation, double* translation,
                   CeresBlocks blocks = CeresBlocks::kSquareRoot, int threads = 1);
  ~CeresScanProblem();
  CeresScanProblem(const CeresScanProblem&) = delete;
  CeresScanProblem& operator=(const CeresScanProblem&) = delete;

  // Makes the problem hold exactly the terms of `correspondences` weighted
  // for `w_rcs` (the geometric terms when w_rcs < 1, the RCS terms when > 0).
  void Update(const Correspondences& correspondences, double w_rcs);
  ceres::Problem& problem();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace radargauss
