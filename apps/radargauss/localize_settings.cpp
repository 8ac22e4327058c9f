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

namespace {

// Our solvers, plus the PCL peers when built with RADARGAUSS_WITH_PCL.
std::vector<std::string> SolverNames() {
  std::vector<std::string> names = ScanMatcherNames();
#ifdef RADARGAUSS_HAVE_PCL
  names.push_back("pcl-ndt");
  names.push_back("pcl-gicp");
#endif
  return names;
}

}  // namespace

std::string FormatWeight(double w) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", w);
  return text;
}

namespace {

void AddSweepOptions(CLI::App* app, LocalizeSettings& s) {
  app->add_option("--w-rcs", s.w_rcs, "Weights w_rcs of eq. 2 to sweep (0..1)")
      ->delimiter(',')
      ->check(InRange(0.0, 1.0))
      ->capture_default_str();
  app->add_option("--solver", s.solvers,
                  "Solvers: " + Joined(ScanMatcherNames()) +
                      " (and pcl-ndt, pcl-gicp when built "
                      "with RADARGAUSS_WITH_PCL)")
      ->delimiter(',')
      ->check(CLI::IsMember(SolverNames()).description("{" + Joined(ScanMatcherNames(), ",") + "[,pcl-ndt,pcl-gicp]}"))
      ->capture_default_str();
  app->add_option("--loss", s.losses, "Geometric losses: " + Joined(LossNames()))
      ->delimiter(',')
      ->check(CLI::IsMember(LossNames()))
      ->capture_default_str();
  app->add_option("--loss-scale", s.loss_scale, "Scale of the geometric loss")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--rcs-loss", s.rcs_loss, "RCS loss (the paper: cauchy)")
      ->check(CLI::IsMember(LossNames()))
      ->capture_default_str();
  app->add_option("--rcs-loss-scale", s.rcs_loss_scale, "Scale of the RCS loss")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--rcs-likelihood", s.rcs_likelihood,
                  "RCS residual: decibel (the paper), swerling1 or swerling3 (fluctuating RCS)")
      ->check(CLI::IsMember(RcsLikelihoodNames()))
      ->capture_default_str();
  AddBoolFlag(app, "--rcs-confidence", s.rcs_confidence,
              "Weigh each RCS term by its Gaussian's fit (spread and members)");
  app->add_option("--rcs-expected-spread", s.rcs_expected_spread,
                  "The spread (dB) the confidence expects (0: the likelihood's own)")
      ->check(NonNegative())
      ->capture_default_str();
  AddBoolFlag(app, "--w-rcs-from-map", s.w_rcs_from_map,
              "Also match with each map's data-chosen w_rcs (configuration gn-wmap...)");
  app->add_option("--incidences", s.incidences, "Incidence models to sweep (map built here)")
      ->delimiter(',')
      ->check(CLI::IsMember(IncidenceModelNames()));
  app->add_option("--degrees", s.degrees, "SH degrees to sweep (map built here)")
      ->delimiter(',')
      ->check(InRange(0, kMaxShDegree));
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

void AddCoarseOptions(CLI::App* app, LocalizeSettings& s) {
  app->add_option("--coarse-levels", s.coarse_levels,
                  "Coarse-to-fine levels: merged (voxel merges, the default) or inflated (every Gaussian blurred)")
      ->check(CLI::IsMember(CoarseLevelsNames()))
      ->capture_default_str();
  app->add_option("--coarse-voxel", s.coarse_voxel,
                  "Coarse levels match the scan's voxel centroids, voxel side this times the level's blur "
                  "(0: the points)")
      ->check(NonNegative())
      ->capture_default_str();
  app->add_option("--coarse-points", s.coarse_points, "Points used on the coarse levels (0: all)")
      ->check(NonNegative())
      ->capture_default_str();
  app->add_option("--coarse-gate", s.coarse_gate,
                  "Association gate on the coarse levels (Mahalanobis; smaller: faster, less reach)")
      ->check(InRange(kMinCoarseGate, kMaxCoarseGate))
      ->capture_default_str();
  AddBoolFlag(app, "--loss-curvature", s.loss_curvature,
              "Own GN: the robust losses' curvature in the Hessian instead of IRLS weights alone");
  AddBoolFlag(app, "--geometric-first", s.geometric_first,
              "With 0 < w < 1: the exact map's geometric term alone first, then eq. 2 (default on)");
  AddBoolFlag(
      app, "--no-geometric-first", [&s](bool on) { s.geometric_first = !on; }, "--geometric-first=false");
}

}  // namespace

const SequenceOptions& LocalizeSettings::CheckedSequenceOptions() const {
  if (sequence.ground_truth.empty()) throw DataError("localize needs --gt");
  return sequence;
}

void LocalizeSettings::CheckAgainst(const Sequence& sequence) const { CheckRcsWeights(sequence, w_rcs); }

RcsTermOptions LocalizeSettings::RcsTerms() const {
  RcsTermOptions options;
  options.likelihood = RcsLikelihoodFromString(rcs_likelihood);
  options.confidence = rcs_confidence;
  options.expected_spread_db = rcs_expected_spread;
  return options;
}

std::vector<std::pair<double, bool>> LocalizeSettings::Weights(const GaussianMap& map) const {
  std::vector<std::pair<double, bool>> weights;
  for (const double w : w_rcs) weights.emplace_back(w, false);
  if (w_rcs_from_map) weights.emplace_back(RcsWeightFromMap(SummariseRcs(map, RcsTerms())), true);
  return weights;
}

MatchingMapOptions LocalizeSettings::MatchingOptions() const {
  MatchingMapOptions options;
  options.coarse = CoarseLevelsFromString(coarse_levels);
  options.coarse_gate = coarse_gate;
  return options;
}

radargauss::MatchOptions LocalizeSettings::Configuration(const std::string& solver, double w,
                                                         const std::string& loss) const {
  radargauss::MatchOptions options;
  options.solver = SolverKindFromString(solver);
  options.matching.w_rcs = w;
  options.matching.geometric_loss = {LossTypeFromString(loss), loss_scale};
  options.matching.rcs_loss = {LossTypeFromString(rcs_loss), rcs_loss_scale};
  options.matching.rcs_terms = RcsTerms();
  options.matching.coarse_voxel_per_sigma = coarse_voxel;
  options.matching.coarse_points = coarse_points;
  options.matching.geometric_first = geometric_first;
  options.gauss_newton.loss_curvature = loss_curvature;
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
  AddCoarseOptions(app, s);
  app->add_option("--ndt-resolution", s.ndt_resolution, "pcl-ndt: voxel of the NDT peer (m)")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--ndt-step", s.ndt_step, "pcl-ndt: line-search step of the NDT peer (m)")
      ->check(Positive())
      ->capture_default_str();
}

}  // namespace radargauss::cli
