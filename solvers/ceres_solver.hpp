// Scan matching with Ceres (DESIGN.md section 5): the same residual functors
// in a ceres::Problem with a rotation block (SO3Manifold) and a translation
// block, eq. 2's weights as ScaledLoss around each term's robust loss, a
// dense linear solver; an outer loop re-associates between solves.
// Rotation-only RCS: the RCS residuals take the rotation block only, the
// translation a constant of the current association.
#pragma once

#include "solvers/scan_matcher.hpp"

namespace radargauss {

struct CeresSolverOptions {
  bool dogleg = false;           // Levenberg-Marquardt (default) or dogleg
  int max_inner_iterations = 10; // Ceres iterations per association
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
