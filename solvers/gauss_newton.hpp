// The own Gauss-Newton scan matcher (DESIGN.md section 5): per outer
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

#include <Eigen/Core>

#include "solvers/scan_matcher.hpp"

namespace radargauss {

// One linearisation: H = sum w J^T J, g = sum w J^T r over the tangent
// [dt; dphi], and the number of residuals.
struct LinearSystem {
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  std::size_t residuals = 0;
  double rho_sum = 0.0;  // sum of rho(s) over the residuals: the term's cost before eq. 2's weight
  // With ScanMatchingOptions::loss_curvature: what the losses' curvature adds
  // to H (sum of c (J^T r)(J^T r)^T, c = max(2 rho'', -rho'/s)); else zero.
  Eigen::Matrix<double, 6, 6> loss_curvature = Eigen::Matrix<double, 6, 6>::Zero();
};

// The geometric and RCS systems at `pose` for fixed correspondences (public
// so that tests and benchmarks can compare the analytic and autodiff paths).
LinearSystem BuildGeometricSystem(const Correspondences& correspondences, const SE3d& pose,
                                  const ScanMatchingOptions& options);
LinearSystem BuildRcsSystem(const Correspondences& correspondences, const SE3d& pose,
                            const ScanMatchingOptions& options);

class GaussNewtonSolver final : public ScanMatcher {
 public:
  explicit GaussNewtonSolver(const ScanMatchingOptions& options);
  std::string Name() const override;
  ScanMatchingResult Match(const RadarScan& scan, const MatchingMap& map,
                           const SE3d& initial) const override;

 private:
  ScanMatchingOptions options_;
};

}  // namespace radargauss
