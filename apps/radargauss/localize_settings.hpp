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
  std::vector<double> w_rcs = {0.0, 0.25, 1.0};
  std::vector<std::string> solvers = {"gn"};
  std::vector<std::string> losses = {"trivial"};
  std::vector<std::string> incidences;
  std::vector<int> degrees;
  std::string rcs_loss = "cauchy";
  std::string rcs_likelihood = ToString(RcsLikelihood::kDecibel);
  bool rcs_confidence = false;
  double rcs_expected_spread = 0.0;  // dB; 0: the likelihood's own
  bool w_rcs_from_map = false;       // add each map's data-chosen weight (RcsWeightFromMap) to the sweep
  double loss_scale = 1.0;
  double rcs_loss_scale = 1.0;
  double max_translation = 2.0;
  double max_rotation = 5.0;
  std::uint32_t seed = 42;
  int stride = 1;
  std::string shard;  // "I/N": this run matches the I-th of N parts of the scans
  std::string coarse_levels = ToString(MatchingMapOptions().coarse);
  double coarse_voxel = ScanMatchingOptions().coarse_voxel_per_sigma;
  std::size_t coarse_points = ScanMatchingOptions().coarse_points;
  double coarse_gate = MatchingMapOptions().coarse_gate;
  bool loss_curvature = false;
  bool geometric_first = ScanMatchingOptions().geometric_first;
  double ndt_resolution = 1.0;  // m: the PCL NDT peer's voxel
  double ndt_step = 0.1;        // m: its line-search step

  // The sequence options, once the flags that a run needs are checked.
  const SequenceOptions& CheckedSequenceOptions() const;
  // Throws DataError when the sequence cannot serve the settings (a weight
  // w > 0 on scans without RCS), before any map is built.
  void CheckAgainst(const Sequence& sequence) const;
  MatchingMapOptions MatchingOptions() const;
  RcsTermOptions RcsTerms() const;
  // The weights of the sweep for `map`: --w-rcs and, with --w-rcs-from-map,
  // the map's own (flagged true).
  std::vector<std::pair<double, bool>> Weights(const GaussianMap& map) const;
  // The options of one configuration: solver, weight w and geometric loss.
  radargauss::MatchOptions Configuration(const std::string& solver, double w, const std::string& loss) const;
};

void AddLocalizeOptions(CLI::App* app, LocalizeSettings& settings);

}  // namespace radargauss::cli
