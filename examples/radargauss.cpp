// radargauss: the command-line tool. Every subcommand prints a one-line
// error and exits non-zero on bad input (flags, files); nothing crashes.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>

#include "radargauss/doppler.hpp"
#include "radargauss/error.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/io/sequence.hpp"
#include "radargauss/simulator.hpp"

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

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (info->parsed()) return RunInfo(info_options);
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
