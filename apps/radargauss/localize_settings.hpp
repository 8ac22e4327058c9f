// SPDX-License-Identifier: BSD-3-Clause
// The flags of radargauss localize and the options they make.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/residuals/rcs_likelihood.hpp"
#include "radargauss/solvers/factory.hpp"
#include "radargauss/solvers/scan_matcher.hpp"

namespace radargauss::cli {

struct LocalizeSettings {
  SequenceOptions sequence;
  MapBuildSettings build;
  std::string map_path;
  std::string out;
  // The match's options (MatchOptionTable's rows) and the matching map's
  // (MatchingMapOptionTable's), and the sweep over three match rows: one
  // run per solver, weight and geometric loss (as given: validated words).
  radargauss::MatchOptions match;
  MatchingMapOptions matching_map;
  std::vector<std::string> solvers = {"gn"};
  std::vector<std::string> w_rcs = {"0", "0.25", "1"};
  std::vector<std::string> losses = {"trivial"};
  std::vector<std::string> incidences;
  std::vector<int> degrees;
  bool w_rcs_from_map = false;  // add each map's data-chosen weight (RcsWeightFromMap) to the sweep
  double max_translation = 2.0;
  double max_rotation = 5.0;
  std::uint32_t seed = 42;
  int stride = 1;
  std::string shard;            // "I/N": this run matches the I-th of N parts of the scans
  double ndt_resolution = 1.0;  // m: the PCL NDT peer's voxel
  double ndt_step = 0.1;        // m: its line-search step

  // The sequence options, once the flags that a run needs are checked.
  const SequenceOptions& CheckedSequenceOptions() const;
  // Throws DataError when the sequence cannot serve the settings (a weight
  // w > 0 on scans without RCS), before any map is built.
  void CheckAgainst(const Sequence& sequence) const;
  // The weights of the sweep for `map`: --w-rcs and, with --w-rcs-from-map,
  // the map's own (flagged true).
  std::vector<std::pair<double, bool>> Weights(const GaussianMap& map) const;
  // The options of one configuration: solver, weight w and geometric loss.
  radargauss::MatchOptions Configuration(const std::string& solver, double w, const std::string& loss) const;
  // --w-rcs's weights as numbers.
  std::vector<double> SweptWeights() const;
};

void AddLocalizeOptions(CLI::App* app, LocalizeSettings& settings);

}  // namespace radargauss::cli
