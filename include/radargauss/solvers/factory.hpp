// SPDX-License-Identifier: BSD-3-Clause
// Solvers by kind or name, so that the front door, the command-line tool,
// tests and benchmarks build them one way. One table (factory.cpp) holds
// every kind's name; the lists the tool prints are derived from it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "radargauss/solvers/scan_matcher.hpp"
#include "radargauss/solvers/solver_options.hpp"

namespace radargauss {

enum class SolverKind {
  kGaussNewton,          // "gn": the own Gauss-Newton, analytic Jacobians
  kGaussNewtonAutoDiff,  // "gn-autodiff": the same with Jets through the functors
  kCeres,                // "ceres": Ceres Levenberg-Marquardt on the same residuals
  kCeresDogleg,          // "ceres-dogleg": Ceres dogleg
  kMultiHypothesis,      // "mh-gn": several starts, each refined by the own Gauss-Newton
};

std::string ToString(SolverKind kind);
SolverKind SolverKindFromString(const std::string& name);  // throws std::invalid_argument
const std::vector<std::string>& ScanMatcherNames();        // every kind's name, in enum order

// Everything a match is configured by: the solver and its options.
struct MatchOptions {
  SolverKind solver = SolverKind::kGaussNewton;
  ScanMatchingOptions matching;       // eq. 2, losses, association, stopping rules
  GaussNewtonOptions gauss_newton;    // kGaussNewton, kGaussNewtonAutoDiff, kMultiHypothesis
  CeresSolverOptions ceres;           // kCeres (kCeresDogleg sets dogleg)
  MultiHypothesisOptions hypotheses;  // kMultiHypothesis
};

// Its options (options.hpp): the solver, eq. 2's and the solvers' own (gn_*, ceres_*, mh_*).
const OptionTable<MatchOptions>& MatchOptionTable();

// Throws std::invalid_argument for bad options.
std::unique_ptr<ScanMatcher> MakeScanMatcher(const MatchOptions& options);
// The same from a name of ScanMatcherNames() (throws for an unknown one).
std::unique_ptr<ScanMatcher> MakeScanMatcher(const std::string& name, const ScanMatchingOptions& options);

}  // namespace radargauss
