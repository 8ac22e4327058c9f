// SPDX-License-Identifier: BSD-3-Clause
// Scan matching with Ceres (docs/design/solvers.md, "Ceres"): the same residual functors
// in a ceres::Problem with a rotation block (SO3Manifold) and a translation
// block, eq. 2's weights as ScaledLoss, a dense linear solver; an outer loop
// re-associates between solves.
// Rotation-only RCS: the RCS residuals take the rotation block only, the
// translation a constant of the current association.
#pragma once

#include "radargauss/solvers/scan_matcher.hpp"
#include "radargauss/solvers/solver_options.hpp"

namespace radargauss {

class CeresSolver final : public ScanMatcher {
 public:
  CeresSolver(const ScanMatchingOptions& options, const CeresSolverOptions& ceres_options = {});
  std::string Name() const override;
  using ScanMatcher::Match;
  ScanMatchingResult Match(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                           const ScanPriors& priors) const override;

 private:
  ScanMatchingOptions options_;
  CeresSolverOptions ceres_options_;
};

}  // namespace radargauss
