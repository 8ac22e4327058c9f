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
  // Ceres iterations per solve, i.e. per association, in the stages that
  // steer (the coarse levels and, with geometric_first, the exact map's
  // geometric stage). Few: the outer loop re-associates after each solve
  // there, and iterating a fresh association to full convergence pays
  // Jacobian evaluations for terms about to change.
  int max_inner_iterations = 2;
  // In the match's last stage (eq. 2 on the exact map) a solve ends once the
  // pose has moved past the association's re-association thresholds (the
  // outer loop's lazy rule, ScanMatchingOptions, checked after each
  // iteration), once an accepted step is below the loop's step tolerances
  // (as the own GN stops), once Ceres converges, or after this many
  // iterations: what the loop would do over several solves on an
  // association it keeps runs in one, without a solve's set-up and first
  // Jacobian each time. A match ends only once such a solve settled (Ceres
  // converged or the step was small) on an association the loop keeps (more
  // solves on it when this limit cuts one short).
  int max_exact_inner_iterations = 8;
  // How analytic terms enter the problem (see CeresScanProblem): by default
  // the terms of a kind share a residual block per thread, handed to Ceres in
  // its square-root form; kShared and kPerTerm are the plainer layouts, for
  // comparison (bench/RESULTS.md times all three).
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
