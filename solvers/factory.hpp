// Solvers by name, so that the command-line tool, tests and benchmarks build
// them one way: gn, gn-autodiff, ceres, ceres-dogleg, mh-gn (8 starts).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "solvers/scan_matcher.hpp"

namespace radargauss {

const std::vector<std::string>& ScanMatcherNames();

// Throws std::invalid_argument for an unknown name or bad options.
std::unique_ptr<ScanMatcher> MakeScanMatcher(const std::string& name, const ScanMatchingOptions& options);

}  // namespace radargauss
