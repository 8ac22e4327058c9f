// SPDX-License-Identifier: BSD-3-Clause
// radargauss slam: radar odometry with loop closure on a pose graph and one
// Gaussian-RCS map of the place from the optimised trajectory
// (docs/design/slam.md, "SLAM"), evaluated against a reference when one is given.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "commands.hpp"
#include "odometry_settings.hpp"
#include "option_flags.hpp"
#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/experiment/evaluation.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/map_tiles.hpp"
#include "radargauss/core/progress.hpp"
#include "radargauss/slam/radar_slam.hpp"

namespace radargauss::cli {

namespace {

struct SlamSettings {
  OdometrySettings odometry;  // the run's inputs; the odometry's options are slam.odometry
  SlamOptions slam;
  FalseLoopStudy study;
  bool no_map = false;
  double map_tiles = 0.0;  // m; 0: no tiles
};

int RunSlam(const SlamSettings& settings) {
  SlamSettings s = settings;
  s.no_map = s.no_map || !s.slam.hold_map_points;  // --hold-map-points=false: no map to build
  s.slam.hold_map_points = !s.no_map;
  const SlamOptions& options = s.slam;
  ValidateOptions(options);
  // The scans are read twice: for the checks, then one at a time into the
  // run, so memory is bounded by the place, not the drive (--mcap holds them).
  const bool stream = s.odometry.mcap.empty();
  RunInputs inputs = LoadRunInputs(s.odometry, options.odometry.match.matching.w_rcs, !stream);
  const Sequence& sequence = inputs.sequence;
  const std::optional<Trajectory>& reference = inputs.reference;
  if (s.map_tiles > 0.0 && s.no_map) throw DataError("--map-tiles writes the map: drop --no-map");
  StagedFolder folder = RunFolder(s.odometry, {"slam.tum", "odometry", "map.rgm", "map.ply", "map_tiles"});
  const ImuInput imu = ImuOf(s.odometry);  // before the run: a bad IMU leaves nothing behind
  if (!imu.samples.empty()) {
    CheckOverlap(imu.samples, sequence, s.odometry.imu_topic.empty() ? "" : "; try --imu-stamps record");
  }
  RadarSlam slam(options, s.study, MakeMotionModel(imu.inertial, imu.radar_from_imu, imu.samples));
  const auto register_scan = [&](const RadarScan& scan) { slam.Register(scan); };
  if (stream) {
    StreamScans(s.odometry, "slam", sequence.scans.size(), register_scan);
  } else {
    RegisterScans(sequence, "slam", register_scan);
  }
  slam.Finish();
  GaussianMap map;
  try {
    if (!s.no_map) map = BuildPlaceMap(slam);
  } catch (const DataError& e) {  // no static point in the whole run: known only now
    throw DataError(std::string(e.what()) + " in " + SequenceName(s.odometry.sequence) +
                    " (static: Doppler inliers within --ego-min-range to --ego-max-range; --no-map writes the "
                    "trajectory without a map)");
  }
  const std::string out = folder.path();
  WriteOdometry((std::filesystem::path(out) / "odometry").string(), slam.odometry());
  WriteSlam(out, slam);
  if (!s.no_map) {
    WriteMap((std::filesystem::path(out) / "map.rgm").string(), map);
    ExportPly((std::filesystem::path(out) / "map.ply").string(), map);
    if (s.map_tiles > 0.0) WriteMapTiles((std::filesystem::path(out) / "map_tiles").string(), map, s.map_tiles);
  }
  std::string tables;
  if (reference) {
    WriteEvaluation((std::filesystem::path(out) / "odometry").string(),
                    EvaluateTrajectory(slam.odometry().trajectory(), *reference));
    tables = WriteEvaluation(out, EvaluateTrajectory(slam.trajectory(), *reference));
  }
  folder.Commit();
  if (!s.odometry.mcap.empty()) WriteRunForViewer(s.odometry.out, sequence.scans, reference, s.odometry.mcap);
  const SlamSummary summary = Summarise(slam);
  std::printf(
      "slam: %zu scans, %zu keyframes, %zu candidates compared, %zu verified, %zu loops (%zu false injected); place "
      "recognition %.2f ms per keyframe (median); map of %zu Gaussians\n",
      sequence.scans.size(), summary.keyframes, summary.compared, summary.verified, summary.loops, summary.injected,
      summary.describe_ms + summary.search_ms, map.gaussians.size());
  std::printf("per scan: median %.2f ms, p90 %.2f, p99 %.2f, max %.1f; the back end's p99 %.2f ms, max %.1f\n",
              summary.total_median_ms, summary.total_p90_ms, summary.total_p99_ms, summary.total_max_ms,
              summary.back_end_p99_ms, summary.back_end_max_ms);
  std::printf("back end (%s): per keyframe median %.2f ms, p99 %.2f, max %.1f\n",
              summary.asynchronous ? "beside the odometry" : "in each scan's time", summary.keyframe_median_ms,
              summary.keyframe_p99_ms, summary.keyframe_max_ms);
  std::printf("%s", tables.c_str());
  std::printf("wrote %s (slam.tum, keyframes.csv, loops.csv, per_scan.csv, slam.json%s%s, odometry/%s)\n",
              s.odometry.out.c_str(), s.no_map ? "" : ", map.rgm, map.ply", s.map_tiles > 0.0 ? ", map_tiles/" : "",
              reference ? ", evaluation.json, evaluation.md" : "");
  return 0;
}

}  // namespace

Subcommand AddSlam(CLI::App& parent) {
  auto s = std::make_shared<SlamSettings>();
  CLI::App* app = parent.add_subcommand("slam", "Radar SLAM: odometry, loop closure, one map of the place");
  AddSequenceOptions(app, s->odometry.sequence, "--gt",
                     "Reference trajectory (TUM, or BAG:/topic[:child] of a ROS 2 bag), for the evaluation only");
  app->add_option("--out", s->odometry.out, "Output folder")->required();
  AddTableOptions(app, SlamOptionTable(), s->slam, OdometryListedElsewhere());
  AddTableOptions(app, FalseLoopStudyOptionTable(), s->study);
  AddImuOptions(app, s->odometry);
  AddTableOptions(app, RadarInertialOptionTable(), s->odometry.inertial);
  AddRunOptions(app, s->odometry);
  s->odometry.app = app;
  AddBoolFlag(app, "--no-map", s->no_map, "Write no map of the place (trajectories and loops only)");
  app->add_option("--map-tiles", s->map_tiles,
                  "Also write the map as square tiles of this many metres (map_tiles/, for relocalize and localize)")
      ->check(NonNegative())
      ->group(HelpGroup(OptionGroup::kTuning));  // --help-all
  return {app, [s] { return RunSlam(*s); }};
}

}  // namespace radargauss::cli
