#include "solvers/factory.hpp"

#include <stdexcept>

#include "solvers/ceres_solver.hpp"
#include "solvers/gauss_newton.hpp"
#include "solvers/multi_hypothesis.hpp"

namespace radargauss {

const std::vector<std::string>& ScanMatcherNames() {
  static const std::vector<std::string> names = {"gn", "gn-autodiff", "ceres", "ceres-dogleg", "mh-gn"};
  return names;
}

std::unique_ptr<ScanMatcher> MakeScanMatcher(const std::string& name, const ScanMatchingOptions& options) {
  ScanMatchingOptions o = options;
  if (name == "gn") return std::make_unique<GaussNewtonSolver>(o);
  if (name == "gn-autodiff") {
    o.jacobians = JacobianMode::kAutoDiff;
    return std::make_unique<GaussNewtonSolver>(o);
  }
  if (name == "ceres") return std::make_unique<CeresSolver>(o);
  if (name == "ceres-dogleg") {
    CeresSolverOptions ceres;
    ceres.dogleg = true;
    return std::make_unique<CeresSolver>(o, ceres);
  }
  if (name == "mh-gn") return std::make_unique<MultiHypothesisSolver>(std::make_shared<GaussNewtonSolver>(o), o);
  throw std::invalid_argument("unknown solver '" + name + "' (gn, gn-autodiff, ceres, ceres-dogleg, mh-gn)");
}

}  // namespace radargauss
