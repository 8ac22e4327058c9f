// SPDX-License-Identifier: BSD-3-Clause
// radargauss simulate: write a synthetic 4D radar sequence.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.hpp"
#include "option_flags.hpp"
#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/bag_writer.hpp"
#include "radargauss/simulator/simulator.hpp"

namespace radargauss::cli {

namespace {

struct SimulateSettings {
  std::string out;
  std::string config;
  std::string rig_config;  // a rig of radars instead of one
  std::uint32_t seed = 1;
  bool seed_given = false;
  int scans = 0;
  bool force = false;
  std::string bag;  // --mcap: the sequence as a ROS 2 bag too
};

// One simulation per radar of the rig config, written as a rig file's folders.
int RunSimulateRig(const SimulateSettings& s) {
  if (!s.config.empty()) throw DataError("--rig-config holds the world (world:): drop --config");
  if (!s.bag.empty()) throw DataError("--mcap writes one radar's sequence: a rig is written as folders");
  RigSimulationConfig config = LoadRigSimulationConfig(s.rig_config);
  if (s.seed_given) {
    for (std::size_t r = 0; r < config.radars.size(); ++r) config.radars[r].second.seed += s.seed - config.world.seed;
    config.world.seed = s.seed;
  }
  if (s.scans > 0) config.world.scans = s.scans;
  namespace fs = std::filesystem;
  std::error_code error;
  if (!s.force && fs::exists(fs::path(s.out) / "rig.yaml", error)) {
    throw FileError(s.out, "already holds a rig (use --force to overwrite)");
  }
  StagedFolder folder(s.out);
  const SimulatedRig rig = SimulateRig(config);
  WriteSimulatedRig(folder.path(), rig);
  folder.Commit();
  std::printf("simulated a rig of %zu radars over %.1f s into %s (rig.yaml, gt_body_tum.txt%s)\n", rig.radars.size(),
              double(config.world.scans) / config.world.rate_hz, s.out.c_str(),
              rig.imu.empty() ? "" : "; the body's IMU: imu.txt, imu_extrinsic.txt with T_body_imu");
  for (std::size_t r = 0; r < rig.radars.size(); ++r) {
    std::size_t detections = 0;
    for (const RadarScan& scan : rig.radars[r].scans) detections += scan.points.size();
    std::printf("  %s: %zu scans at %g Hz, %zu detections, clock offset %g s\n", rig.names[r].c_str(),
                rig.radars[r].scans.size(), rig.radars[r].config.rate_hz, detections,
                rig.radars[r].config.clock_offset);
  }
  return 0;
}

int RunSimulate(const SimulateSettings& s) {
  if (!s.rig_config.empty()) return RunSimulateRig(s);
  SimulationConfig config = s.config.empty() ? SimulationConfig{} : LoadSimulationConfig(s.config);
  if (s.seed_given) config.seed = s.seed;
  if (s.scans > 0) config.scans = s.scans;
  namespace fs = std::filesystem;
  const fs::path points = fs::path(s.out) / "ars548" / "points";
  std::error_code error;
  if (!s.force && fs::exists(points, error) && !fs::is_empty(points, error)) {
    throw FileError(s.out, "already holds a sequence (use --force to overwrite)");
  }
  const std::string extension = fs::path(s.bag).extension().string();
  if (!s.bag.empty() && extension != ".mcap" && extension != ".db3") {
    throw DataError("--mcap " + s.bag + ": name a .mcap or .db3 file");
  }
  StagedFolder folder(s.out);  // with --force, the new scans replace the old ones whole
  const SimulatedSequence sequence = Simulate(config);
  WriteSimulatedSequence(folder.path(), sequence);
  if (!s.bag.empty()) {
    // The scans as the folder gives them back, so that both inputs are the same sequence.
    SequenceOptions written;
    written.sequence_dir = folder.path();
    WriteRos2Bag(s.bag, extension == ".mcap" ? BagFormat::kMcap : BagFormat::kSqlite3, LoadSequence(written).scans,
                 sequence.imu, &sequence.ground_truth);
  }
  folder.Commit();
  std::size_t detections = 0;
  for (const RadarScan& scan : sequence.scans) detections += scan.points.size();
  std::printf("simulated %zu scans, %zu detections (seed %u) into %s\n", sequence.scans.size(), detections, config.seed,
              s.out.c_str());
  std::printf("ground truth: %s/gt_radar_tum.txt (radar frame; use --extrinsic identity)\n", s.out.c_str());
  if (!s.bag.empty()) {
    std::printf("bag: %s (/radar/points, /reference/pose%s)\n", s.bag.c_str(),
                sequence.imu.empty() ? "" : ", /imu/data");
  }
  if (!sequence.imu.empty()) {
    std::printf("imu: %s/imu.txt (%zu samples at %g Hz), imu_extrinsic.txt (T_radar_imu), imu_biases.txt (the truth)\n",
                s.out.c_str(), sequence.imu.size(), config.imu_rate_hz);
  }
  return 0;
}

}  // namespace

Subcommand AddSimulate(CLI::App& parent) {
  auto s = std::make_shared<SimulateSettings>();
  CLI::App* app = parent.add_subcommand("simulate", "Write a synthetic 4D radar sequence");
  app->add_option("--out", s->out, "Output folder (Snail-Radar layout)")->required();
  app->add_option("--config", s->config, "YAML parameters (see configs/synthetic_world.yaml)");
  app->add_option("--rig-config", s->rig_config,
                  "A rig of radars instead (see configs/rig_five_radars.yaml): a folder per radar, rig.yaml, "
                  "gt_body_tum.txt");
  CLI::Option* seed = app->add_option("--seed", s->seed, "Random seed");
  app->add_option("--scans", s->scans, "Number of scans (overrides the config)")->check(Positive());
  AddBoolFlag(app, "--force", s->force, "Overwrite an existing sequence in --out");
  app->add_option("--mcap", s->bag, "Also write the sequence as a ROS 2 bag (.mcap, or .db3), as convert does");
  return {app, [s, seed] {
            s->seed_given = seed->count() > 0;
            return RunSimulate(*s);
          }};
}

}  // namespace radargauss::cli
