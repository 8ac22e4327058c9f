// SPDX-License-Identifier: BSD-3-Clause
// The paper's localisation experiment (section IV, docs/design/experiment.md, "The localisation experiment"): for
// every scan, start from the reference pose composed with a seeded random
// error (translation magnitude uniform in [0, max] m, rotation angle uniform in
// [0, max] deg, random directions; the same errors for every configuration),
// match against the map, and report errors per configuration.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "radargauss/lie/se3.hpp"
#include "radargauss/core/stats.hpp"
#include "radargauss/core/types.hpp"
#include "radargauss/solvers/scan_matcher.hpp"

namespace radargauss {

// The most initial errors one call makes: ten million scans.
constexpr std::size_t kMaxInitialErrors = 10000000;

// The seeded initial errors: one perturbation per scan, X_initial = X_ref * E.
// Throws std::invalid_argument past kMaxInitialErrors scans or for a
// negative or non-finite largest error.
std::vector<SE3d> InitialErrors(std::size_t scans, double max_translation, double max_rotation_deg, std::uint32_t seed);

// Translation (m) and rotation (deg) error of an estimate.
void PoseErrors(const SE3d& estimate, const SE3d& reference, double& translation, double& rotation_deg);

struct ScanOutcome {
  std::size_t scan = 0;
  double time = 0.0;
  double initial_translation_error = 0.0;
  double initial_rotation_error_deg = 0.0;
  double translation_error = 0.0;
  double rotation_error_deg = 0.0;
  ScanMatchingResult result;
};

struct ConfigurationRun {
  std::string name;  // e.g. gn-w0.25-trivial-offset-L3
  double w_rcs = 0.0;
  std::vector<ScanOutcome> outcomes;
  ErrorStatistics translation, rotation;
  double mean_iterations = 0.0, mean_time_ms = 0.0, converged_share = 0.0;
  void Summarise();
};

// Matches every scan from reference * error with `matcher`; parallel over
// scans, the same results for any thread count. Outcome k is numbered
// first_scan + k (a shard's scans keep the experiment's numbers).
ConfigurationRun RunConfiguration(const std::string& name, double w_rcs, const ScanMatcher& matcher,
                                  const MatchingMap& map, const std::vector<RadarScan>& scans,
                                  const std::vector<SE3d>& references, const std::vector<SE3d>& errors,
                                  std::size_t first_scan = 0);

// One shard of an experiment (docs/design/experiment.md, "Shards"): shard `index` of
// `count` (1-based) matches scans [Begin, End) of `scans` in all.
struct Shard {
  std::size_t index = 1, count = 1;
  std::size_t Begin(std::size_t scans) const { return (index - 1) * scans / count; }
  std::size_t End(std::size_t scans) const { return index * scans / count; }
};
// "I/N" with 1 <= I <= N; throws std::invalid_argument.
Shard ParseShard(const std::string& text);

// What makes two shards parts of one experiment: named values (every flag
// that changes results, the sequence's and the map's checksums), compared
// as text by the merge.
using ExperimentIdentity = std::vector<std::pair<std::string, std::string>>;

// shard.json in `dir`: the experiment's identity, which shard and its scan
// range, and every outcome's numbers and poses exactly (doubles that read
// back bit for bit), with the reference pose of each scan, so that merged
// shards give the files one run writes.
void WriteShard(const std::string& dir, const Shard& shard, std::size_t total_scans, const ExperimentIdentity& identity,
                const std::vector<ConfigurationRun>& runs, const std::vector<SE3d>& references);
// The runs of the whole experiment from the folders of all its shards (any
// order), and the reference pose of every scan. Throws DataError naming the
// folder (and the field) for a malformed shard.json, a missing, repeated or
// foreign shard (another identity or count), or a shard whose range or
// outcomes are not the ones its index gives.
std::vector<ConfigurationRun> MergeShards(const std::vector<std::string>& dirs, std::vector<SE3d>& references);

// Writes per_scan.csv, summary.json, table.md and trajectories/<name>.tum into
// `dir` (created). Returns the Markdown table (best per column in bold).
std::string WriteExperimentResults(const std::string& dir, const std::vector<ConfigurationRun>& runs);

}  // namespace radargauss
