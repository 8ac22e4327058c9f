// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/factory.hpp"

#include <stdexcept>
#include <utility>

#include "radargauss/solvers/gauss_newton.hpp"

namespace radargauss {

namespace {

const std::pair<SolverKind, const char*> kSolverNames[] = {
    {SolverKind::kGaussNewton, "gn"},
    {SolverKind::kGaussNewtonAutoDiff, "gn-autodiff"},
    {SolverKind::kCeres, "ceres"},
    {SolverKind::kCeresDogleg, "ceres-dogleg"},
    {SolverKind::kMultiHypothesis, "mh-gn"},
};

std::string JoinedNames() {
  std::string joined;
  for (const std::string& name : ScanMatcherNames()) joined += (joined.empty() ? "" : ", ") + name;
  return joined;
}

}  // namespace

std::string ToString(SolverKind kind) {
  for (const auto& [k, name] : kSolverNames) {
    if (k == kind) return name;
  }
  throw std::invalid_argument("unknown solver kind");
}

SolverKind SolverKindFromString(const std::string& name) {
  for (const auto& [kind, n] : kSolverNames) {
    if (name == n) return kind;
  }
  throw std::invalid_argument("unknown solver '" + name + "' (" + JoinedNames() + ")");
}

const std::vector<std::string>& ScanMatcherNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all;
    for (const auto& entry : kSolverNames) all.push_back(entry.second);
    return all;
  }();
  return names;
}

std::unique_ptr<ScanMatcher> MakeScanMatcher(const MatchOptions& options) {
  ScanMatchingOptions matching = options.matching;
  CeresSolverOptions ceres = options.ceres;
  switch (options.solver) {
    case SolverKind::kGaussNewton:
      return std::make_unique<GaussNewtonSolver>(matching);
    case SolverKind::kGaussNewtonAutoDiff:
      matching.jacobians = JacobianMode::kAutoDiff;
      return std::make_unique<GaussNewtonSolver>(matching);
    case SolverKind::kCeres:
      return std::make_unique<CeresSolver>(matching, ceres);
    case SolverKind::kCeresDogleg:
      ceres.dogleg = true;
      return std::make_unique<CeresSolver>(matching, ceres);
    case SolverKind::kMultiHypothesis:
      return std::make_unique<MultiHypothesisSolver>(std::make_shared<GaussNewtonSolver>(matching), matching,
                                                     options.hypotheses);
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
