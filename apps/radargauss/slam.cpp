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
#include "radargauss/io/rig.hpp"
#include "radargauss/odometry/rig_odometry.hpp"
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

void PrintSlamSummary(const RadarSlam& slam, std::size_t scans, std::size_t gaussians) {
  const SlamSummary summary = Summarise(slam);
  std::printf(
      "slam: %zu scans, %zu keyframes, %zu candidates compared, %zu verified, %zu loops (%zu false injected); place "
      "recognition %.2f ms per keyframe (median); map of %zu Gaussians\n",
      scans, summary.keyframes, summary.compared, summary.verified, summary.loops, summary.injected,
      summary.describe_ms + summary.search_ms, gaussians);
  std::printf("per scan: median %.2f ms, p90 %.2f, p99 %.2f, max %.1f; the back end's p99 %.2f ms, max %.1f\n",
              summary.total_median_ms, summary.total_p90_ms, summary.total_p99_ms, summary.total_max_ms,
              summary.back_end_p99_ms, summary.back_end_max_ms);
  std::printf("back end (%s): per keyframe median %.2f ms, p99 %.2f, max %.1f\n",
              summary.asynchronous ? "beside the odometry" : "in each scan's time", summary.keyframe_median_ms,
              summary.keyframe_p99_ms, summary.keyframe_max_ms);
}

// The map of the place, or a clear error when no point of the run was static.
GaussianMap PlaceMapOf(const RadarSlam& slam, const std::string& what) {
  try {
    return BuildPlaceMap(slam);
  } catch (const DataError& e) {  // no static point in the whole run: known only now
    throw DataError(std::string(e.what()) + " in " + what +
                    " (static: Doppler inliers within --ego-min-range to --ego-max-range; --no-map writes the "
                    "trajectory without a map)");
  }
}

void WriteMaps(const std::string& out, const GaussianMap& map, double tiles) {
  WriteMap((std::filesystem::path(out) / "map.rgm").string(), map);
  ExportPly((std::filesystem::path(out) / "map.ply").string(), map);
  if (tiles > 0.0) WriteMapTiles((std::filesystem::path(out) / "map_tiles").string(), map, tiles);
}

// SLAM on a rig (docs/design/rig.md, "SLAM on a rig"): the rig's frames
// (RigFrames) into one SLAM in the reference radar's frame; body.tum beside
// slam.tum, evaluated against --gt as the body's reference.
int RunRigSlam(const SlamSettings& s) {
  SlamOptions options = s.slam;
  if (!s.odometry.sequence.sequence_dir.empty() || !s.odometry.sequence.bag.empty()) {
    throw DataError("--rig names the radars' scans itself: drop --sequence and --bag");
  }
  if (!s.odometry.mcap.empty()) throw DataError("--rig: no --mcap");
  if (s.map_tiles > 0.0 && s.no_map) throw DataError("--map-tiles writes the map: drop --no-map");
  const Rig rig = ReadRig(s.odometry.rig);
  const ImuInput imu = RigImuOf(s.odometry, rig);  // before the run: a bad IMU leaves nothing behind
  std::optional<Trajectory> reference;
  if (!s.odometry.sequence.ground_truth.empty()) {
    reference = ReadRadarTrajectory(s.odometry.sequence.ground_truth,
                                    ResolveExtrinsic(s.odometry.sequence.extrinsic, s.odometry.sequence.ground_truth));
  }
  StagedFolder folder =
      RunFolder(s.odometry, {"slam.tum", "body.tum", "odometry", "map.rgm", "map.ply", "map_tiles", "rig.yaml"});
  const SE3d& body_from_reference = rig.radars.front().body_from_radar;
  options.odometry = ReferenceRadarOptions(options.odometry, body_from_reference);
  RadarSlam slam(options, s.study,
                 MakeRigMotionModel(imu.inertial, body_from_reference, imu.radar_from_imu, imu.samples));
  Rig calibrated;
  const std::size_t scans = RegisterRigFrames(
      rig, options.odometry,
      [&](const RigFrame& frame) {
        slam.Register(frame.scan, frame.velocity);
        return RegisteredFrame{slam.odometry().pose(slam.odometry().scans() - 1)};
      },
      &calibrated);
  const bool online_calibration = options.odometry.rig.calibrate && rig.radars.size() > 1;
  slam.Finish();
  const GaussianMap map = s.no_map ? GaussianMap() : PlaceMapOf(slam, s.odometry.rig);
  const std::string out = folder.path();
  WriteOdometry((std::filesystem::path(out) / "odometry").string(), slam.odometry());
  WriteSlam(out, slam);
  const Trajectory body = BodyTrajectory(slam.trajectory(), body_from_reference);
  WriteTum((std::filesystem::path(out) / "body.tum").string(), body);
  if (!s.no_map) WriteMaps(out, map, s.map_tiles);
  if (online_calibration) WriteRigWithAbsolutePaths((std::filesystem::path(out) / "rig.yaml").string(), calibrated);
  std::string tables;
  if (reference) {
    WriteEvaluation((std::filesystem::path(out) / "odometry").string(),
                    EvaluateTrajectory(BodyTrajectory(slam.odometry().trajectory(), body_from_reference), *reference));
    tables = WriteEvaluation(out, EvaluateTrajectory(body, *reference));
  }
  folder.Commit();
  std::printf("rig: %zu radars, %zu scans in %zu frames\n", rig.radars.size(), scans, slam.odometry().scans());
  PrintSlamSummary(slam, slam.odometry().scans(), map.gaussians.size());
  std::printf("%s", tables.c_str());
  std::printf(
      "wrote %s (body.tum: T_world_body; slam.tum, keyframes.csv, loops.csv, per_scan.csv, slam.json of the "
      "reference radar%s%s%s, odometry/%s)\n",
      s.odometry.out.c_str(), s.no_map ? "" : ", map.rgm, map.ply", s.map_tiles > 0.0 ? ", map_tiles/" : "",
      online_calibration ? ", rig.yaml: the rig calibrated online" : "",
      reference ? ", evaluation.json, evaluation.md (the body's)" : "");
  return 0;
}

int RunSlam(const SlamSettings& settings) {
  if (!settings.odometry.rig.empty()) {
    SlamSettings s = settings;
    s.no_map = s.no_map || !s.slam.hold_map_points;
    s.slam.hold_map_points = !s.no_map;
    ValidateOptions(s.slam);
    return RunRigSlam(s);
  }
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
  const GaussianMap map = s.no_map ? GaussianMap() : PlaceMapOf(slam, SequenceName(s.odometry.sequence));
  const std::string out = folder.path();
  WriteOdometry((std::filesystem::path(out) / "odometry").string(), slam.odometry());
  WriteSlam(out, slam);
  if (!s.no_map) WriteMaps(out, map, s.map_tiles);
  std::string tables;
  if (reference) {
    WriteEvaluation((std::filesystem::path(out) / "odometry").string(),
                    EvaluateTrajectory(slam.odometry().trajectory(), *reference));
    tables = WriteEvaluation(out, EvaluateTrajectory(slam.trajectory(), *reference));
  }
  folder.Commit();
  if (!s.odometry.mcap.empty()) WriteRunForViewer(s.odometry.out, sequence.scans, reference, s.odometry.mcap);
  PrintSlamSummary(slam, sequence.scans.size(), map.gaussians.size());
  std::printf("%s", tables.c_str());
  std::printf("wrote %s (slam.tum, keyframes.csv, loops.csv, per_scan.csv, slam.json%s%s, odometry/%s)\n",
              s.odometry.out.c_str(), s.no_map ? "" : ", map.rgm, map.ply", s.map_tiles > 0.0 ? ", map_tiles/" : "",
              reference ? ", evaluation.json, evaluation.md" : "");
  return 0;
}

}  // namespace

Subcommand AddSlam(CLI::App& parent) {
  auto s = std::make_shared<SlamSettings>();
  CLI::App* app =
      parent.add_subcommand("slam", "Radar SLAM: odometry, loop closure, one map of the place (of a rig: --rig)");
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
  app->add_option("--rig", s->odometry.rig,
                  "Rig file (docs/design/rig.md): SLAM of the body from every radar's scans instead of --sequence "
                  "(--gt: the body's reference)")
      ->group(HelpGroup(OptionGroup::kTuning));  // --help-all; the command's description names it
  app->add_option("--map-tiles", s->map_tiles,
                  "Also write the map as square tiles of this many metres (map_tiles/, for relocalize and localize)")
      ->check(NonNegative())
      ->group(HelpGroup(OptionGroup::kTuning));  // --help-all
  return {app, [s] { return RunSlam(*s); }};
}

}  // namespace radargauss::cli
