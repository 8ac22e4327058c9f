// radargauss: the command-line tool. Every subcommand prints a one-line
// error and exits non-zero on bad input (flags, files); nothing crashes.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>

#include "radargauss/atomic_file.hpp"
#include "radargauss/doppler.hpp"
#include "radargauss/experiment.hpp"
#include "radargauss/error.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/io/sequence.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/progress.hpp"
#include "radargauss/simulator.hpp"
#include "solvers/factory.hpp"
#ifdef RADARGAUSS_HAVE_PCL
#include "peers/pcl_peers.hpp"
#endif
#include "yaml_config.hpp"

#include <tbb/global_control.h>

namespace {

using namespace radargauss;

// The sequence options shared by every subcommand that reads a sequence.
void AddSequenceOptions(CLI::App* app, SequenceOptions& options) {
  app->add_option("--sequence", options.sequence_dir,
                  "Sequence folder: Snail-Radar layout (ars548/points/*.pcd), *.pcd or *.bin");
  app->add_option("--gt", options.ground_truth, "Ground-truth trajectory (TUM)");
  app->add_option("--extrinsic", options.extrinsic,
                  "T_gt_radar: auto, identity, snail-20231213, or a file 'x y z qx qy qz qw'")
      ->capture_default_str();
  app->add_option("--bag", options.bag, "ROS1 bag with sensor_msgs/PointCloud2 scans");
  app->add_option("--topic", options.topic, "Topic of the scans in --bag");
  app->add_option("--bin-layout", options.bin_layout,
                  "Field order of .bin records (vod = 'x y z rcs v_r v_r_comp time')")
      ->capture_default_str();
  app->add_option("--rcs-field", options.fields.rcs_field,
                  "Field holding RCS (default: first of rcs RCS intensity power; 'none')");
  app->add_option("--doppler-field", options.fields.doppler_field,
                  "Field holding Doppler (default: first of doppler velocity v_r "
                  "radial_velocity vel; 'none')");
  app->add_option("--doppler-sign", options.fields.doppler_sign,
                  "Multiplies the file's Doppler to get 'positive receding' (+1 or -1)")
      ->check(CLI::IsMember({1.0, -1.0}))
      ->capture_default_str();
}

struct Range {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  void Add(double v) {
    min = std::min(min, v);
    max = std::max(max, v);
  }
};

int RunInfo(const SequenceOptions& options) {
  if (!options.bag.empty() && options.topic.empty()) {
    std::printf("bag: %s\n", options.bag.c_str());
    for (const BagTopic& topic : ListBagTopics(options.bag)) {
      std::printf("  %-40s %-28s %zu messages\n", topic.name.c_str(), topic.type.c_str(),
                  topic.messages);
    }
    return 0;
  }
  const Sequence sequence = LoadSequence(options);
  std::vector<std::size_t> counts;
  Range doppler;
  Range rcs;
  bool has_doppler = true;
  bool has_rcs = true;
  bool has_std = true;
  for (const RadarScan& scan : sequence.scans) {
    counts.push_back(scan.points.size());
    has_doppler = has_doppler && scan.has_doppler;
    has_rcs = has_rcs && scan.has_rcs;
    for (const RadarPoint& p : scan.points) {
      doppler.Add(p.doppler);
      rcs.Add(p.rcs);
      has_std = has_std && p.std_dev.has_value();
    }
  }
  std::vector<std::size_t> sorted = counts;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted.size() % 2 ? double(sorted[sorted.size() / 2])
                                          : 0.5 * (sorted[sorted.size() / 2 - 1] + sorted[sorted.size() / 2]);
  std::printf("layout: %s\n", sequence.layout.c_str());
  std::printf("scans: %zu read", sequence.total_scans);
  if (!options.ground_truth.empty()) {
    std::printf(", %zu matched to poses, %zu outside the trajectory's time span",
                sequence.scans.size(), sequence.skipped_scans);
  }
  std::printf("\npoints per scan: min %zu, median %.1f, max %zu\n", sorted.front(), median,
              sorted.back());
  std::printf("fields: xyz%s%s%s\n", has_doppler ? " doppler" : "", has_rcs ? " rcs" : "",
              has_std ? " stds" : "");
  std::printf("time span: %.9f .. %.9f (%.3f s)\n", sequence.scans.front().timestamp,
              sequence.scans.back().timestamp,
              sequence.scans.back().timestamp - sequence.scans.front().timestamp);
  if (has_doppler) std::printf("doppler: %.3f .. %.3f m/s\n", doppler.min, doppler.max);
  if (has_rcs) std::printf("rcs: %.3f .. %.3f dBsm\n", rcs.min, rcs.max);
  if (!sequence.poses.empty()) {
    double length = 0.0;
    for (std::size_t i = 1; i < sequence.poses.size(); ++i) {
      length += (sequence.poses[i].translation() - sequence.poses[i - 1].translation()).norm();
    }
    std::printf("trajectory: %zu poses, %.1f m driven over the matched scans\n",
                sequence.trajectory.size(), length);
  }
  return 0;
}

int RunSimulate(const std::string& out, const std::string& config_path, std::uint32_t seed,
                bool seed_given, int scans, bool force) {
  SimulationConfig config = config_path.empty() ? SimulationConfig{} : LoadSimulationConfig(config_path);
  if (seed_given) config.seed = seed;
  if (scans > 0) config.scans = scans;
  namespace fs = std::filesystem;
  const fs::path points = fs::path(out) / "ars548" / "points";
  std::error_code error;
  if (!force && fs::exists(points, error) && !fs::is_empty(points, error)) {
    throw FileError(out, "already holds a sequence (use --force to overwrite)");
  }
  if (force) fs::remove_all(points, error);
  const SimulatedSequence sequence = Simulate(config);
  WriteSimulatedSequence(out, sequence);
  std::size_t detections = 0;
  for (const RadarScan& scan : sequence.scans) detections += scan.points.size();
  std::printf("simulated %zu scans, %zu detections (seed %u) into %s\n", sequence.scans.size(),
              detections, config.seed, out.c_str());
  std::printf("ground truth: %s/gt_radar_tum.txt (radar frame; use --extrinsic identity)\n",
              out.c_str());
  return 0;
}

// Options of the map-building stages, shared by build-map (and localize later).
struct MapBuildSettings {
  GaussianMapOptions map;
  RcsFitOptions rcs;
  std::string builder = "kmeans";
  std::string incidence = "offset";
  bool no_adaptive = false;
  bool no_doppler_filter = false;
};

void AddMapBuildOptions(CLI::App* app, MapBuildSettings& s) {
  app->add_option("--builder", s.builder, "kmeans (RA-L default) or voxel (NDT-style baseline)")
      ->check(CLI::IsMember({"kmeans", "voxel"}))
      ->capture_default_str();
  app->add_option("--points-per-gaussian", s.map.points_per_gaussian,
                  "K = round(N_downsampled / this) (about 4 for ARS548, 16 for Oculii Eagle)")
      ->check(CLI::Range(1.0, 1e6))
      ->capture_default_str();
  app->add_option("--downsample", s.map.downsample_voxel, "Voxel downsample edge (m)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app->add_option("--em-iterations", s.map.em_iterations, "Hard-EM rounds")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app->add_option("--min-std", s.map.min_std, "Minimum principal std of a Gaussian (m)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app->add_option("--ndt-voxel", s.map.ndt_voxel, "Voxel edge of the voxel builder (m)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app->add_option("--gate", s.map.association_gate, "Association gate tau (Mahalanobis distance)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app->add_option("--map-seed", s.map.seed, "Seed of the bisecting k-means")->capture_default_str();
  app->add_option("--degree", s.rcs.max_degree, "SH degree of the RCS models (0..3)")
      ->check(CLI::Range(0, kMaxShDegree))
      ->capture_default_str();
  app->add_option("--incidence", s.incidence, "Incidence vector: offset (paper) or view")
      ->check(CLI::IsMember({"offset", "view"}))
      ->capture_default_str();
  app->add_flag("--no-adaptive", s.no_adaptive,
                "Give no model instead of lowering the degree when members are too few");
  app->add_flag("--no-doppler-filter", s.no_doppler_filter, "Keep dynamic points too");
}

// The geometric part of a map: static map cloud, Gaussians, members.
struct GaussianStage {
  MapCloud cloud;
  GaussianMap map;
  std::vector<int> association;
  MapCloudStats cloud_stats;
};

GaussianStage BuildGaussianStage(const Sequence& sequence, MapBuildSettings& s) {
  s.map.builder = MapBuilderFromString(s.builder);
  MapCloudOptions cloud_options;
  cloud_options.doppler_filter = !s.no_doppler_filter;
  GaussianStage stage;
  stage.cloud = BuildMapCloud(sequence, cloud_options, &stage.cloud_stats);
  if (stage.cloud.points.empty()) throw DataError("no static points to build a map from");
  ProgressBar bar;
  stage.map.gaussians = BuildGaussians(
      stage.cloud.points, s.map,
      [&](const char* step, std::size_t done, std::size_t total) { bar.Update(step, done, total); },
      &stage.association);
  bar.Finish();
  return stage;
}

// The RCS models of a Gaussian stage for one incidence model and degree.
GaussianMap FitRcsStage(const GaussianStage& stage, const MapBuildSettings& s, IncidenceModel incidence,
                        int degree, bool verbose) {
  GaussianMap map = stage.map;
  RcsFitOptions rcs = s.rcs;
  rcs.incidence = incidence;
  rcs.max_degree = degree;
  rcs.adaptive = !s.no_adaptive;
  const RcsFitStats stats = FitRcsModels(map, stage.cloud, stage.association, rcs);
  if (verbose) {
    std::printf("rcs models (%s incidence, degree <= %d, %s): %zu with a model (%zu at a lowered "
                "degree), %zu without; mean fit RMSE %.4f\n",
                ToString(incidence).c_str(), degree, rcs.adaptive ? "adaptive" : "fixed", stats.with_model,
                stats.lowered_degree, stats.no_model, stats.mean_fit_rmse);
  }
  return map;
}

// Sequence -> static map cloud -> Gaussians -> RCS models.
GaussianMap BuildMapFromSequence(const Sequence& sequence, MapBuildSettings s, bool verbose) {
  const GaussianStage stage = BuildGaussianStage(sequence, s);
  if (verbose) {
    std::printf("map cloud: %zu scans (%zu without ego velocity), %zu of %zu points static\n",
                stage.cloud_stats.scans, stage.cloud_stats.scans_without_ego_velocity,
                stage.cloud_stats.points_static, stage.cloud_stats.points_in);
    std::printf("gaussians: %zu (%s builder)\n", stage.map.gaussians.size(), s.builder.c_str());
  }
  return FitRcsStage(stage, s, IncidenceModelFromString(s.incidence), s.rcs.max_degree, verbose);
}

// ---------------------------------------------------------------------------
// localize: the paper's experiment.

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
  double loss_scale = 1.0;
  double rcs_loss_scale = 1.0;
  double max_translation = 2.0;
  double max_rotation = 5.0;
  std::uint32_t seed = 42;
  int stride = 1;
  std::string coarse_levels = "inflated";
  double coarse_voxel = ScanMatchingOptions().coarse_voxel_per_sigma;
  std::size_t coarse_points = ScanMatchingOptions().coarse_points;
  double coarse_gate = MatchingMapOptions().coarse_gate;
  bool loss_curvature = false;
  bool geometric_first = ScanMatchingOptions().geometric_first;
};

// Our solvers, plus the PCL peers when built with RADARGAUSS_WITH_PCL.
std::vector<std::string> SolverNames() {
  std::vector<std::string> names = ScanMatcherNames();
#ifdef RADARGAUSS_HAVE_PCL
  names.push_back("pcl-ndt");
  names.push_back("pcl-gicp");
#endif
  return names;
}

void AddLocalizeOptions(CLI::App* app, LocalizeSettings& s) {
  AddSequenceOptions(app, s.sequence);
  AddMapBuildOptions(app, s.build);
  app->add_option("--map", s.map_path, "Map file (.rgm); without it the map is built from the sequence");
  app->add_option("--out", s.out, "Results folder")->required();
  app->add_option("--w-rcs", s.w_rcs, "Weights w_rcs of eq. 2 to sweep (0..1)")
      ->delimiter(',')
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app->add_option("--solver", s.solvers,
                  "Solvers: gn, gn-autodiff, ceres, ceres-dogleg, mh-gn (and pcl-ndt, pcl-gicp when built "
                  "with RADARGAUSS_WITH_PCL)")
      ->delimiter(',')
      ->check(CLI::IsMember(SolverNames()))
      ->capture_default_str();
  app->add_option("--loss", s.losses, "Geometric losses: trivial, huber, cauchy, geman-mcclure, tukey")
      ->delimiter(',')
      ->check(CLI::IsMember({"trivial", "huber", "cauchy", "geman-mcclure", "tukey"}))
      ->capture_default_str();
  app->add_option("--loss-scale", s.loss_scale, "Scale of the geometric loss")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app->add_option("--rcs-loss", s.rcs_loss, "RCS loss (the paper: cauchy)")
      ->check(CLI::IsMember({"trivial", "huber", "cauchy", "geman-mcclure", "tukey"}))
      ->capture_default_str();
  app->add_option("--rcs-loss-scale", s.rcs_loss_scale, "Scale of the RCS loss")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app->add_option("--incidences", s.incidences, "Incidence models to sweep (map built here)")
      ->delimiter(',')
      ->check(CLI::IsMember({"offset", "view"}));
  app->add_option("--degrees", s.degrees, "SH degrees to sweep (map built here)")
      ->delimiter(',')
      ->check(CLI::Range(0, kMaxShDegree));
  app->add_option("--max-translation", s.max_translation, "Initial translation error bound (m)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app->add_option("--max-rotation", s.max_rotation, "Initial rotation error bound (deg)")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  app->add_option("--seed", s.seed, "Seed of the initial errors")->capture_default_str();
  app->add_option("--stride", s.stride, "Match every n-th scan (the map uses all)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app->add_option("--coarse-levels", s.coarse_levels,
                  "Coarse-to-fine levels: inflated (every Gaussian blurred) or merged (voxel merges, faster)")
      ->check(CLI::IsMember({"inflated", "merged"}))
      ->capture_default_str();
  app->add_option("--coarse-voxel", s.coarse_voxel,
                  "Coarse levels match the scan's voxel centroids, voxel side this times the level's blur "
                  "(0: the points)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app->add_option("--coarse-points", s.coarse_points, "Points used on the coarse levels (0: all)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app->add_option("--coarse-gate", s.coarse_gate,
                  "Association gate on the coarse levels (Mahalanobis; smaller: faster, less reach)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app->add_flag("--loss-curvature", s.loss_curvature,
                "Own GN: the robust losses' curvature in the Hessian instead of IRLS weights alone");
  app->add_flag("--geometric-first,!--no-geometric-first", s.geometric_first,
                "With 0 < w < 1: the exact map's geometric term alone first, then eq. 2 (default on)");
}

std::string FormatWeight(double w) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", w);
  return text;
}

int RunLocalize(LocalizeSettings s) {
  if (s.sequence.ground_truth.empty()) throw DataError("localize needs --gt");
  const Sequence sequence = LoadSequence(s.sequence);
  // The maps to match against: one per (incidence, degree).
  std::vector<GaussianMap> maps;
  if (!s.map_path.empty()) {
    if (!s.incidences.empty() || !s.degrees.empty()) {
      throw DataError("--incidences/--degrees need the map built here (drop --map)");
    }
    maps.push_back(ReadMap(s.map_path));
    s.degrees = {s.build.rcs.max_degree};
  } else {
    if (s.incidences.empty()) s.incidences = {s.build.incidence};
    if (s.degrees.empty()) s.degrees = {s.build.rcs.max_degree};
    const GaussianStage stage = BuildGaussianStage(sequence, s.build);
    std::printf("map: %zu Gaussians from %zu static points\n", stage.map.gaussians.size(),
                stage.cloud.points.size());
    for (const std::string& incidence : s.incidences) {
      for (const int degree : s.degrees) {
        maps.push_back(FitRcsStage(stage, s.build, IncidenceModelFromString(incidence), degree, true));
      }
    }
  }
  std::vector<RadarScan> scans;
  std::vector<SE3d> references;
  for (std::size_t k = 0; k < sequence.scans.size(); k += std::size_t(s.stride)) {
    scans.push_back(sequence.scans[k]);
    references.push_back(sequence.poses[k]);
  }
  const std::vector<SE3d> errors = InitialErrors(scans.size(), s.max_translation, s.max_rotation, s.seed);
  std::vector<ConfigurationRun> runs;
  std::vector<Eigen::Vector3d> map_cloud;  // the PCL peers' target
  ProgressBar bar;
  std::size_t total = 0, done = 0;
  for (std::size_t m = 0; m < maps.size(); ++m) total += s.solvers.size() * s.losses.size() * s.w_rcs.size();
  for (std::size_t m = 0; m < maps.size(); ++m) {
    MatchingMapOptions matching_options;
    matching_options.coarse = CoarseLevelsFromString(s.coarse_levels);
    matching_options.coarse_gate = s.coarse_gate;
    const MatchingMap matching(maps[m], matching_options);
    const int degree = s.map_path.empty() ? s.degrees[m % s.degrees.size()] : s.degrees[0];
    for (const std::string& solver : s.solvers) {
      if (solver.rfind("pcl-", 0) == 0) {
#ifdef RADARGAUSS_HAVE_PCL
        // Peers: the merged map cloud as the target, once (no w_rcs, no loss).
        if (m > 0) continue;
        if (map_cloud.empty()) map_cloud = BuildMapCloud(sequence).points;
        const PclPeerMatcher peer(solver == "pcl-ndt" ? PclMethod::kNdt : PclMethod::kGicp, map_cloud);
        bar.Update("localize", done, total);
        runs.push_back(RunConfiguration(solver, 0.0, peer, matching, scans, references, errors));
        ++done;
#endif
        continue;
      }
      for (const std::string& loss : s.losses) {
        for (const double w : s.w_rcs) {
          ScanMatchingOptions options;
          options.w_rcs = w;
          options.geometric_loss = {LossTypeFromString(loss), s.loss_scale};
          options.rcs_loss = {LossTypeFromString(s.rcs_loss), s.rcs_loss_scale};
          options.coarse_voxel_per_sigma = s.coarse_voxel;
          options.coarse_points = s.coarse_points;
          options.loss_curvature = s.loss_curvature;
          options.geometric_first = s.geometric_first;
          const auto matcher = MakeScanMatcher(solver, options);
          const std::string name = solver + "-w" + FormatWeight(w) + "-" + loss + "-" +
                                   ToString(maps[m].incidence) + "-L" + std::to_string(degree);
          bar.Update("localize", done, total);
          runs.push_back(RunConfiguration(name, w, *matcher, matching, scans, references, errors));
          ++done;
        }
      }
    }
  }
  bar.Update("localize", done, total);
  bar.Finish();
  const std::string table = WriteExperimentResults(s.out, runs);
  // For the plots: the reference trajectory and the map's Gaussian means.
  Trajectory reference;
  for (std::size_t k = 0; k < scans.size(); ++k) {
    if (reference.empty() || scans[k].timestamp > reference.EndTime()) reference.Append(scans[k].timestamp, references[k]);
  }
  namespace fs = std::filesystem;
  WriteTum((fs::path(s.out) / "reference.tum").string(), reference);
  WriteFileAtomically((fs::path(s.out) / "map_means.csv").string(), [&](std::ostream& out) {
    out << "x,y,z\n";
    for (const Gaussian& g : maps.front().gaussians) out << g.mean.x() << ',' << g.mean.y() << ',' << g.mean.z() << '\n';
  });
  double initial_t = 0.0;
  for (const ScanOutcome& o : runs.front().outcomes) initial_t += o.initial_translation_error;
  std::printf("%zu scans, %zu configurations; initial errors: mean %.3f m (uniform in [0, %g] m, [0, %g] deg)\n\n%s\n",
              scans.size(), runs.size(), initial_t / std::max<std::size_t>(1, scans.size()), s.max_translation,
              s.max_rotation, table.c_str());
  std::printf("results: %s (per_scan.csv, summary.json, table.md, trajectories/); plots: "
              "scripts/plot_results.py %s --reference %s/reference.tum\n",
              s.out.c_str(), s.out.c_str(), s.out.c_str());
  return 0;
}

int RunMapInfo(const std::string& path) {
  const GaussianMap map = ReadMap(path);
  std::array<std::size_t, kMaxShDegree + 1> histogram{};
  std::size_t with_model = 0;
  std::size_t members = 0;
  double rmse = 0.0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY);
  Eigen::Vector3d hi = -lo;
  for (const Gaussian& g : map.gaussians) {
    members += g.point_count;
    lo = lo.cwiseMin(g.mean);
    hi = hi.cwiseMax(g.mean);
    if (g.rcs.valid()) {
      ++with_model;
      ++histogram[g.rcs.degree];
      rmse += g.rcs.fit_rmse;
    }
  }
  const std::size_t n = map.gaussians.size();
  std::printf("map: %s (version %u)\n", path.c_str(), kMapFileVersion);
  std::printf("gaussians: %zu, member points: %zu\n", n, members);
  std::printf("incidence model: %s\n", ToString(map.incidence).c_str());
  std::printf("rcs coverage: %zu of %zu (%.1f%%) have a model\n", with_model, n,
              n ? 100.0 * double(with_model) / double(n) : 0.0);
  std::printf("sh degree histogram: none %zu", n - with_model);
  for (int d = 0; d <= kMaxShDegree; ++d) std::printf(", %d: %zu", d, histogram[d]);
  std::printf("\nmean fit RMSE (normalised): %.4f\n", with_model ? rmse / double(with_model) : 0.0);
  if (n) {
    std::printf("extent: x %.2f..%.2f, y %.2f..%.2f, z %.2f..%.2f m\n", lo.x(), hi.x(), lo.y(),
                hi.y(), lo.z(), hi.z());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"radargauss: 4D radar Gaussian-RCS maps and scan matching"};
  app.require_subcommand(1);

  SequenceOptions info_options;
  CLI::App* info = app.add_subcommand("info", "Summarise a sequence (or list a bag's topics)");
  AddSequenceOptions(info, info_options);

  std::string sim_out;
  std::string sim_config;
  std::uint32_t sim_seed = 1;
  int sim_scans = 0;
  bool sim_force = false;
  CLI::App* simulate = app.add_subcommand("simulate", "Write a synthetic 4D radar sequence");
  simulate->add_option("--out", sim_out, "Output folder (Snail-Radar layout)")->required();
  simulate->add_option("--config", sim_config, "YAML parameters (see configs/synthetic_world.yaml)");
  CLI::Option* seed_option = simulate->add_option("--seed", sim_seed, "Random seed");
  simulate->add_option("--scans", sim_scans, "Number of scans (overrides the config)")
      ->check(CLI::PositiveNumber);
  simulate->add_flag("--force", sim_force, "Overwrite an existing sequence in --out");

  SequenceOptions build_sequence;
  MapBuildSettings build_settings;
  std::string build_out;
  std::string build_ply;
  CLI::App* build_map = app.add_subcommand("build-map", "Build a Gaussian-RCS map of a sequence");
  AddSequenceOptions(build_map, build_sequence);
  AddMapBuildOptions(build_map, build_settings);
  build_map->add_option("--out", build_out, "Map file (.rgm)")->required();
  build_map->add_option("--ply", build_ply, "Also export a 3DGS-layout PLY");

  std::string info_map;
  CLI::App* map_info = app.add_subcommand("map-info", "Summarise a map file");
  map_info->add_option("map", info_map, "Map file (.rgm)")->required();

  LocalizeSettings localize_settings;
  CLI::App* localize = app.add_subcommand("localize", "The paper's localisation experiment (w_rcs sweep)");
  AddLocalizeOptions(localize, localize_settings);

  int threads = 0;
  app.add_option("--threads", threads, "Worker threads (0: all cores)")->check(CLI::NonNegativeNumber);
  // info, build-map and localize read a YAML file of their flags with
  // --config (simulate's --config is the world's parameters); flags given on
  // the command line override the file.
  std::string section;
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "info" || word == "build-map" || word == "localize" || word == "map-info") {
      section = word;
      break;
    }
  }
  app.set_config("--config", "", "YAML file of the subcommand's flags (info, build-map, localize)");
  app.config_formatter(std::make_shared<YamlConfig>(section));
  app.allow_config_extras(CLI::config_extras_mode::error);
  for (CLI::App* command : {info, build_map, localize}) command->fallthrough();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  std::unique_ptr<tbb::global_control> thread_limit;
  if (threads > 0) {
    thread_limit = std::make_unique<tbb::global_control>(
        tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  }
  try {
    if (info->parsed()) return RunInfo(info_options);
    if (map_info->parsed()) return RunMapInfo(info_map);
    if (localize->parsed()) return RunLocalize(localize_settings);
    if (build_map->parsed()) {
      if (build_sequence.ground_truth.empty()) throw DataError("build-map needs --gt");
      const Sequence sequence = LoadSequence(build_sequence);
      const GaussianMap map = BuildMapFromSequence(sequence, build_settings, true);
      WriteMap(build_out, map);
      if (!build_ply.empty()) ExportPly(build_ply, map);
      std::printf("wrote %s%s%s\n", build_out.c_str(), build_ply.empty() ? "" : " and ",
                  build_ply.c_str());
      return 0;
    }
    if (simulate->parsed()) {
      return RunSimulate(sim_out, sim_config, sim_seed, seed_option->count() > 0, sim_scans,
                         sim_force);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "radargauss: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
