// SPDX-License-Identifier: BSD-3-Clause
// The own Gauss-Newton scan matcher (docs/design/solvers.md, "The own Gauss-Newton"): per outer
// iteration, re-associate (lazily on the exact map: CoarseToFine),
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

#include "radargauss/solvers/scan_matcher.hpp"
#include "radargauss/solvers/solver_options.hpp"

namespace radargauss {

class GaussNewtonSolver final : public ScanMatcher {
 public:
  // Throws std::invalid_argument for bad options.
  explicit GaussNewtonSolver(const ScanMatchingOptions& options, const GaussNewtonOptions& gauss_newton = {});
  std::string Name() const override;
  using ScanMatcher::Match;
  ScanMatchingResult Match(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                           const ScanPriors& priors) const override;

 private:
  ScanMatchingOptions options_;
  GaussNewtonOptions gauss_newton_;
};

}  // namespace radargauss
