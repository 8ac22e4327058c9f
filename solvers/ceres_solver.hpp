// Scan matching with Ceres (DESIGN.md section 5): the same residual functors
// in a ceres::Problem with a rotation block (SO3Manifold) and a translation
// block, eq. 2's weights as ScaledLoss, a dense linear solver; an outer loop
// re-associates between solves.
// Rotation-only RCS: the RCS residuals take the rotation block only, the
// translation a constant of the current association.
#pragma once

#include <ceres/problem.h>

#include <memory>

#include "solvers/scan_matcher.hpp"

namespace radargauss {

struct CeresSolverOptions {
  bool dogleg = false;           // Levenberg-Marquardt (default) or dogleg
  // Ceres iterations per solve, i.e. per association, in the stages that
  // steer (the coarse levels and, with geometric_first, the exact map's
  // geometric stage). Few: the outer loop re-associates after each solve
  // there, and iterating a fresh association to full convergence pays
  // Jacobian evaluations for terms about to change. RESULTS.md has 1-5.
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
  // Analytic terms share residual blocks of CeresScanProblem::kTermsPerBlock
  // terms, each term's robust loss applied in its own residual (the cost and
  // gradient of eq. 2; see CeresScanProblem). False: a residual block per
  // term under Ceres's own loss handling, as autodiff terms always have.
  bool shared_blocks = true;
  int threads = 1;
  // Ceres's stopping rules per association (Ceres's defaults; the outer
  // loop's step tolerances decide convergence of the match).
  double function_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
};

// The ceres::Problem of one match, kept across associations: the pose blocks
// (rotation with SO3Manifold, translation) and the terms of the current
// association, with eq. 2's weights as ScaledLoss.
//
// Shared blocks (analytic terms, `shared_blocks`): kTermsPerBlock terms of a
// kind per residual block, so that Ceres's per-block work (evaluator loop,
// manifold product, loss correction, checks, preprocessing) is paid per
// block of terms. Ceres applies a block's loss to the block's squared norm,
// so each term's robust loss rho goes into its own residual instead:
// r -> sqrt(rho(s)/s) r with s = |r|^2, whose squared norm is rho(s), and that
// residual's exact Jacobian. Cost and gradient are eq. 2's, as with a block
// per term; the Gauss-Newton model is that of the rescaled residual, where
// Ceres's loss correction would take sqrt(rho') J (IRLS, for every loss here).
//
// Otherwise (autodiff terms, or shared_blocks = false) a block per term under
// ScaledLoss(its loss); Update re-targets the blocks it keeps at the new
// terms and adds or removes blocks only for the change in count, so Ceres's
// per-block set-up is paid about once per match instead of once per
// association.
class CeresScanProblem {
 public:
  static constexpr std::size_t kTermsPerBlock = 64;

  // `rotation` (quaternion x y z w) and `translation` are the parameter
  // blocks; they must outlive the problem.
  CeresScanProblem(const ScanMatchingOptions& options, double* rotation, double* translation,
                   bool shared_blocks = true);
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
