// SPDX-License-Identifier: BSD-3-Clause
#include "localize_settings.hpp"

#include <algorithm>
#include <cstdio>

#include "option_flags.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/experiment/experiment.hpp"
#include "radargauss/core/names.hpp"
#include "radargauss/residuals/loss.hpp"
#include "radargauss/solvers/factory.hpp"

namespace radargauss::cli {

std::string FormatWeight(double w) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", w);
  return text;
}

namespace {

// MatchOptionTable less the rows the sweep reads.
const OptionTable<radargauss::MatchOptions>& UnsweptMatchRows() {
  static const OptionTable<radargauss::MatchOptions> rows =
      TableWithout(MatchOptionTable(), {"solver", "w_rcs", "loss"});
  return rows;
}

void AddSweepOptions(CLI::App* app, LocalizeSettings& s) {
  // The PCL peers are named in every build (the help is the same); a build
  // without PCL refuses them when the run reaches them.
  AddSweepOption(app, MatchOptionTable(), "solver", s.solvers, {"pcl-ndt", "pcl-gicp"});
  AddSweepOption(app, MatchOptionTable(), "w_rcs", s.w_rcs);
  AddSweepOption(app, MatchOptionTable(), "loss", s.losses);
  AddBoolFlag(app, "--w-rcs-from-map", s.w_rcs_from_map,
              "Also match with each map's data-chosen w_rcs (configuration gn-wmap...)");
  app->add_option("--incidences", s.incidences, "Incidence models to sweep (map built here)")
      ->delimiter(',')
      ->check(CLI::IsMember(IncidenceModelNames()));
  app->add_option("--degrees", s.degrees, "SH degrees to sweep (map built here)")
      ->delimiter(',')
      ->check(InRange(0, kMaxShDegree));
  AddTableOptions(app, UnsweptMatchRows(), s.match);
  AddTableOptions(app, MatchingMapOptionTable(), s.matching_map);
  AddDeprecatedAlias(app, UnsweptMatchRows(), s.match, "--coarse-voxel", "coarse_voxel_per_sigma");
  AddDeprecatedAlias(app, UnsweptMatchRows(), s.match, "--loss-curvature", "gn_loss_curvature");
  AddBoolFlag(
      app, "--no-geometric-first", [&s](bool on) { s.match.matching.geometric_first = !on; },
      "--geometric-first=false");
}

void AddInitialErrorOptions(CLI::App* app, LocalizeSettings& s) {
  app->add_option("--max-translation", s.max_translation, "Initial translation error bound (m)")
      ->check(NonNegative())
      ->capture_default_str();
  app->add_option("--max-rotation", s.max_rotation, "Initial rotation error bound (deg)")
      ->check(InRange(0.0, 180.0))
      ->capture_default_str();
  app->add_option("--seed", s.seed, "Seed of the initial errors")->capture_default_str();
  app->add_option("--stride", s.stride, "Match every n-th scan (the map uses all)")
      ->check(Positive())
      ->capture_default_str();
}

}  // namespace

const SequenceOptions& LocalizeSettings::CheckedSequenceOptions() const {
  if (sequence.ground_truth.empty()) throw DataError("localize needs --gt");
  return sequence;
}

void LocalizeSettings::CheckAgainst(const Sequence& sequence) const { CheckRcsWeights(sequence, SweptWeights()); }

std::vector<double> LocalizeSettings::SweptWeights() const {
  std::vector<double> weights;
  for (const std::string& word : w_rcs) {
    radargauss::MatchOptions options;
    SetRow(MatchOptionTable(), "w_rcs", word, options);
    weights.push_back(options.matching.w_rcs);
  }
  return weights;
}

std::vector<std::pair<double, bool>> LocalizeSettings::Weights(const GaussianMap& map) const {
  std::vector<std::pair<double, bool>> weights;
  for (const double w : SweptWeights()) weights.emplace_back(w, false);
  if (w_rcs_from_map) weights.emplace_back(RcsWeightFromMap(SummariseRcs(map, match.matching.rcs_terms)), true);
  return weights;
}

radargauss::MatchOptions LocalizeSettings::Configuration(const std::string& solver, double w,
                                                         const std::string& loss) const {
  radargauss::MatchOptions options = match;
  SetRow(MatchOptionTable(), "solver", solver, options);
  options.matching.w_rcs = w;
  SetRow(MatchOptionTable(), "loss", loss, options);
  return options;
}

void AddLocalizeOptions(CLI::App* app, LocalizeSettings& s) {
  AddSequenceOptions(app, s.sequence);
  AddMapBuildOptions(app, s.build);
  app->add_option("--map", s.map_path,
                  "Map file (.rgm) or folder of map tiles; without it the map is built from the sequence");
  app->add_option("--out", s.out, "Results folder")->required();
  app->add_option("--shard", s.shard,
                  "I/N: match the I-th of N equal parts of the scans and write shard.json too; "
                  "`radargauss merge` joins the N folders into one run's results")
      ->check([](const std::string& text) {
        try {
          ParseShard(text);
          return std::string();
        } catch (const std::invalid_argument& e) {
          return std::string(e.what());
        }
      });
  AddSweepOptions(app, s);
  AddInitialErrorOptions(app, s);
  app->add_option("--ndt-resolution", s.ndt_resolution, "pcl-ndt: voxel of the NDT peer (m)")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--ndt-step", s.ndt_step, "pcl-ndt: line-search step of the NDT peer (m)")
      ->check(Positive())
      ->capture_default_str();
}

}  // namespace radargauss::cli
