// SPDX-License-Identifier: BSD-3-Clause
// radargauss slam: radar odometry with loop closure on a pose graph and one
// Gaussian-RCS map of the place from the optimised trajectory
// (docs/design.md, "SLAM"), evaluated against a reference when one is given.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "commands.hpp"
#include "odometry_settings.hpp"
#include "radargauss/atomic_file.hpp"
#include "radargauss/error.hpp"
#include "radargauss/evaluation.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/progress.hpp"
#include "radargauss/slam/radar_slam.hpp"

namespace radargauss::cli {

namespace {

struct SlamSettings {
  OdometrySettings odometry;
  SlamOptions slam;
  PlaceRecognitionSettings place_recognition;
  bool no_map = false;
  std::string loop_rejection = ToString(PoseGraphOptions().loop_rejection);
  std::string loop_loss = ToString(PoseGraphOptions().loop_loss.type);
  std::string graph_initialization = ToString(PoseGraphOptions().initialization);
};

SlamOptions Resolved(const SlamSettings& s) {
  if (s.odometry.matcher != "gaussians") throw DataError("slam: --matcher must be gaussians");
  SlamOptions o = s.slam;
  o.odometry = Resolved(s.odometry);
  o.place_recognition = s.place_recognition.Resolved();
  o.graph.loop_rejection = LoopRejectionFromString(s.loop_rejection);
  o.graph.loop_loss.type = LossTypeFromString(s.loop_loss);
  o.graph.initialization = GraphInitializationFromString(s.graph_initialization);
  return o;
}

int RunSlam(const SlamSettings& s) {
  const SlamOptions options = Resolved(s);
  ValidateOptions(options);
  RunInputs inputs = LoadRunInputs(s.odometry, options.odometry.match.matching.w_rcs);
  const Sequence& sequence = inputs.sequence;
  const std::optional<Trajectory>& reference = inputs.reference;
  StagedFolder folder = RunFolder(s.odometry, {"slam.tum", "odometry", "map.rgm", "map.ply"});
  RadarSlam slam(options);
  RegisterScans(sequence, "slam", [&](const RadarScan& scan) { slam.Register(scan); });
  slam.Finish();
  GaussianMap map;
  try {
    if (!s.no_map) map = BuildPlaceMap(sequence.scans, slam);
  } catch (const DataError& e) {  // no static point in the whole run: known only now
    throw DataError(std::string(e.what()) + " in " + SequenceName(s.odometry.sequence) +
                    " (--no-map writes the trajectory without a map)");
  }
  const std::string out = folder.path();
  WriteOdometry((std::filesystem::path(out) / "odometry").string(), slam.odometry());
  WriteSlam(out, slam);
  if (!s.no_map) {
    WriteMap((std::filesystem::path(out) / "map.rgm").string(), map);
    ExportPly((std::filesystem::path(out) / "map.ply").string(), map);
  }
  std::string tables;
  if (reference) {
    WriteEvaluation((std::filesystem::path(out) / "odometry").string(),
                    EvaluateTrajectory(slam.odometry().trajectory(), *reference));
    tables = WriteEvaluation(out, EvaluateTrajectory(slam.trajectory(), *reference));
  }
  folder.Commit();
  const SlamSummary summary = Summarise(slam);
  std::printf(
      "slam: %zu scans, %zu keyframes, %zu candidates compared, %zu verified, %zu loops (%zu false injected); place "
      "recognition %.2f ms per keyframe (median); map of %zu Gaussians\n",
      sequence.scans.size(), summary.keyframes, summary.compared, summary.verified, summary.loops, summary.injected,
      summary.describe_ms + summary.search_ms, map.gaussians.size());
  std::printf("%s", tables.c_str());
  std::printf("wrote %s (slam.tum, keyframes.csv, loops.csv, slam.json%s, odometry/%s)\n", s.odometry.out.c_str(),
              s.no_map ? "" : ", map.rgm, map.ply", reference ? ", evaluation.json, evaluation.md" : "");
  return 0;
}

void AddSlamOptions(CLI::App* app, SlamSettings& s) {
  SlamOptions& o = s.slam;
  app->add_option("--submap-distance", o.submap_distance, "A keyframe every this many metres driven")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--min-loop-path", o.min_loop_path, "Metres driven between a loop's keyframes at least")
      ->check(NonNegative())
      ->capture_default_str();
  AddPlaceRecognitionOptions(app, s.place_recognition);
  app->add_flag("--no-map", s.no_map, "Write no map of the place (trajectories and loops only)");
  app->add_option("--false-loop-rate", o.false_loop_rate,
                  "Robustness studies: the share of keyframes given an injected false loop (0: none)")
      ->check(InRange(0.0, 1.0))
      ->capture_default_str();
  app->add_option("--false-loop-seed", o.false_loop_seed, "Seed of the injected false loops")->capture_default_str();
  app->add_option("--loop-rejection", s.loop_rejection, "Loop edges: loss, switchable or graduated")
      ->check(CLI::IsMember(LoopRejectionNames()))
      ->capture_default_str();
  app->add_option("--loop-loss", s.loop_loss, "Loss of the loop edges (loop rejection 'loss'; graduated: its scale)")
      ->check(CLI::IsMember(LossNames()))
      ->capture_default_str();
  app->add_option("--loop-loss-scale", o.graph.loop_loss.scale, "Scale of the loop loss")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--graph-initialization", s.graph_initialization,
                  "Where each pose-graph solve starts: current (the last optimum and the odometry) or chordal "
                  "(from the edges alone, trusting every loop)")
      ->check(CLI::IsMember(GraphInitializationNames()))
      ->capture_default_str();
}

}  // namespace

Subcommand AddSlam(CLI::App& parent) {
  auto s = std::make_shared<SlamSettings>();
  CLI::App* app = parent.add_subcommand("slam", "Radar SLAM: odometry, loop closure, one map of the place");
  AddSequenceOptions(app, s->odometry.sequence, "--gt", "Reference trajectory (TUM), for the evaluation only");
  app->add_option("--out", s->odometry.out, "Output folder")->required();
  AddOdometryOptions(app, s->odometry);
  AddSlamOptions(app, *s);
  return {app, [s] { return RunSlam(*s); }};
}

}  // namespace radargauss::cli
