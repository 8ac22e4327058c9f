// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/factory.hpp"

#include <stdexcept>
#include <utility>

#include "radargauss/names.hpp"
#include "radargauss/solvers/ceres_solver.hpp"
#include "radargauss/solvers/gauss_newton.hpp"
#include "radargauss/solvers/multi_hypothesis.hpp"

namespace radargauss {

namespace {

const NamedValue<SolverKind> kSolverNames[] = {
    {SolverKind::kGaussNewton, "gn"},        {SolverKind::kGaussNewtonAutoDiff, "gn-autodiff"},
    {SolverKind::kCeres, "ceres"},           {SolverKind::kCeresDogleg, "ceres-dogleg"},
    {SolverKind::kMultiHypothesis, "mh-gn"},
};

const NamedValue<CeresBlocks> kBlocksNames[] = {
    {CeresBlocks::kPerTerm, "per-term"}, {CeresBlocks::kShared, "shared"}, {CeresBlocks::kSquareRoot, "square-root"}};

}  // namespace

std::string ToString(CeresBlocks blocks) { return NameOf(kBlocksNames, blocks); }
CeresBlocks CeresBlocksFromString(const std::string& name) { return ValueNamed(kBlocksNames, name, "Ceres blocks"); }
std::vector<std::string> CeresBlocksNames() { return NamesOf(kBlocksNames); }

std::string ToString(SolverKind kind) { return NameOf(kSolverNames, kind); }
SolverKind SolverKindFromString(const std::string& name) { return ValueNamed(kSolverNames, name, "solver"); }

const std::vector<std::string>& ScanMatcherNames() {
  static const std::vector<std::string> names = NamesOf(kSolverNames);
  return names;
}

std::unique_ptr<ScanMatcher> MakeScanMatcher(const MatchOptions& options) {
  ScanMatchingOptions matching = options.matching;
  CeresSolverOptions ceres = options.ceres;
  switch (options.solver) {
    case SolverKind::kGaussNewton:
      return std::make_unique<GaussNewtonSolver>(matching, options.gauss_newton);
    case SolverKind::kGaussNewtonAutoDiff:
      matching.jacobians = JacobianMode::kAutoDiff;
      return std::make_unique<GaussNewtonSolver>(matching, options.gauss_newton);
    case SolverKind::kCeres:
      return std::make_unique<CeresSolver>(matching, ceres);
    case SolverKind::kCeresDogleg:
      ceres.dogleg = true;
      return std::make_unique<CeresSolver>(matching, ceres);
    case SolverKind::kMultiHypothesis:
      return std::make_unique<MultiHypothesisSolver>(
          std::make_shared<GaussNewtonSolver>(matching, options.gauss_newton), matching, options.hypotheses);
  }
  throw std::invalid_argument("unknown solver kind");
}

std::unique_ptr<ScanMatcher> MakeScanMatcher(const std::string& name, const ScanMatchingOptions& options) {
  MatchOptions match;
  match.solver = SolverKindFromString(name);
  match.matching = options;
  return MakeScanMatcher(match);
}

}  // namespace radargauss
