// SPDX-License-Identifier: BSD-3-Clause
// What each solver has beyond ScanMatchingOptions, as plain values (no
// Ceres header): the own Gauss-Newton's (docs/design/solvers.md, "The own
// Gauss-Newton"), Ceres's (docs/design/solvers.md, "Ceres") and multi-hypothesis
// matching's (docs/design/solvers.md, "Multi-hypothesis matching").
#pragma once

#include <string>
#include <vector>

namespace radargauss {

// What only the own Gauss-Newton has.
struct GaussNewtonOptions {
  int max_step_halvings = 8;  // on the exact map, halvings of a step that raises eq. 2; 0: plain steps
  // The robust losses' curvature in the Hessian: per term J^T (rho' I +
  // 2 rho'' r r^T) J with the curvature along r clamped at 0, where IRLS
  // takes J^T rho' J (the same gradient). For concave losses (Cauchy) IRLS
  // overestimates the curvature and its steps come out short. When the
  // system is not positive definite the step falls back to IRLS. Off: IRLS,
  // as the paper and Ceres (whose Corrector ignores rho'' < 0).
  bool loss_curvature = false;
};

// How analytic terms enter the ceres::Problem (CeresScanProblem); autodiff
// terms always take a residual block each.
enum class CeresBlocks {
  kPerTerm,     // a residual block per term under ScaledLoss(its loss): Ceres's own loss handling
  kShared,      // blocks of CeresScanProblem::kTermsPerBlock terms, each term's loss in its residual
  kSquareRoot,  // shared blocks, each handed to Ceres in its square-root form (default)
};
std::string ToString(CeresBlocks blocks);                    // "per-term", "shared", "square-root"
CeresBlocks CeresBlocksFromString(const std::string& name);  // throws std::invalid_argument
std::vector<std::string> CeresBlocksNames();

// Ceres Levenberg-Marquardt or dogleg on the same residuals.
struct CeresSolverOptions {
  bool dogleg = false;  // Levenberg-Marquardt (default) or dogleg
  // Iterations per solve (per association) in the stages that steer: few, as
  // the outer loop re-associates after each solve there.
  int max_inner_iterations = 2;
  // In the last stage a solve also ends when the pose leaves the association
  // or a step is below the loop's tolerances (docs/design/solvers.md, "Ceres").
  int max_exact_inner_iterations = 8;
  // How analytic terms enter the problem (docs/design/solvers.md, "The residual blocks").
  CeresBlocks blocks = CeresBlocks::kSquareRoot;
  int threads = 1;
  // Ceres's stopping rules per association (Ceres's defaults; the outer
  // loop's step tolerances decide convergence of the match).
  double function_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
};

// Several starts around the initial pose, each refined by an inner solver.
struct MultiHypothesisOptions {
  int starts = 8;            // the first `starts` of HypothesisOffsets' pattern (1..13)
  double xy_offset = 1.0;    // m
  double yaw_offset = 0.05;  // rad
};

}  // namespace radargauss
