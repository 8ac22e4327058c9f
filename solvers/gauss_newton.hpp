// SPDX-License-Identifier: BSD-3-Clause
// The own Gauss-Newton scan matcher (docs/design.md, "The own Gauss-Newton"): per outer
// iteration, re-associate (lazily on the exact map: RunCoarseToFine),
// accumulate H and g per residual with IRLS weights
// rho'(s) from the losses, combine with eq. 2's weights, solve the 6x6 system
// H dx = -g by LDLT, update t += dt, R = R Exp(dphi); stop on a small update
// or at the iteration limit. On the exact map the step is halved (at most
// max_step_halvings times) while it increases eq. 2 for the current
// association, so that the steep RCS term cannot make the iteration oscillate;
// when the next iteration keeps the association, the check uses the cost its
// system carries (the step is taken back and halved there if it raised eq. 2),
// otherwise eq. 2 is evaluated at once. Coarse levels of the MatchingMap take
// plain steps.
//
// Rotation-only RCS (the paper): the rows and columns of the RCS Hessian
// that belong to translation become the identity and its translation
// gradient zero, before the weighted sum. With kFull they are kept.
#pragma once

#include "radargauss/solvers/normal_equations.hpp"
#include "radargauss/solvers/scan_matcher.hpp"

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

class GaussNewtonSolver final : public ScanMatcher {
 public:
  // Throws std::invalid_argument for bad options.
  explicit GaussNewtonSolver(const ScanMatchingOptions& options, const GaussNewtonOptions& gauss_newton = {});
  std::string Name() const override;
  ScanMatchingResult Match(const RadarScan& scan, const MatchingMap& map,
                           const SE3d& initial) const override;

 private:
  ScanMatchingOptions options_;
  GaussNewtonOptions gauss_newton_;
};

}  // namespace radargauss
