// SPDX-License-Identifier: BSD-3-Clause
// Scan matching with Ceres (docs/design.md, "Ceres"): the same residual functors
// in a ceres::Problem with a rotation block (SO3Manifold) and a translation
// block, eq. 2's weights as ScaledLoss, a dense linear solver; an outer loop
// re-associates between solves.
// Rotation-only RCS: the RCS residuals take the rotation block only, the
// translation a constant of the current association.
#pragma once

#include "radargauss/solvers/ceres_scan_problem.hpp"
#include "radargauss/solvers/scan_matcher.hpp"

namespace radargauss {

struct CeresSolverOptions {
  bool dogleg = false;           // Levenberg-Marquardt (default) or dogleg
  // Iterations per solve (per association) in the stages that steer: few, as
  // the outer loop re-associates after each solve there.
  int max_inner_iterations = 2;
  // In the last stage a solve also ends when the pose leaves the association
  // or a step is below the loop's tolerances (docs/design.md, "Ceres").
  int max_exact_inner_iterations = 8;
  // How analytic terms enter the problem (docs/design.md, "The residual blocks").
  CeresBlocks blocks = CeresBlocks::kSquareRoot;
  int threads = 1;
  // Ceres's stopping rules per association (Ceres's defaults; the outer
  // loop's step tolerances decide convergence of the match).
  double function_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
};

class CeresSolver final : public ScanMatcher {
 public:
  CeresSolver(const ScanMatchingOptions& options, const CeresSolverOptions& ceres_options = {});
  std::string Name() const override;
  ScanMatchingResult Match(const RadarScan& scan, const MatchingMap& map,
                           const SE3d& initial) const override;

 private:
  ScanMatchingOptions options_;
  CeresSolverOptions ceres_options_;
};

}  // namespace radargauss
