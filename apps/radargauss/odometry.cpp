// SPDX-License-Identifier: BSD-3-Clause
// radargauss odometry: radar odometry on a map the run builds itself
// (docs/design/odometry.md, "Odometry"), evaluated against a reference when one is given.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "commands.hpp"
#include "odometry_settings.hpp"
#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/stats.hpp"
#include "radargauss/experiment/evaluation.hpp"
#include "radargauss/io/rig.hpp"
#include "radargauss/odometry/mounting.hpp"
#include "radargauss/odometry/rig_odometry.hpp"
#include "radargauss/core/progress.hpp"

namespace radargauss::cli {

namespace {

void PrintSummary(const OdometrySummary& summary) {
  std::printf(
      "odometry: %zu scans (%zu matched, %zu keyframes, %zu with predicted velocity, %zu standing, %zu "
      "with predicted pose), path %.1f m; %.2f ms per scan (median, p90 %.2f); %zu Gaussians active, %zu "
      "in the map\n",
      summary.scans, summary.matched, summary.keyframes, summary.velocity_predicted, summary.standstill,
      summary.pose_predicted, summary.path_length, summary.median_ms, summary.p90_ms, summary.active_gaussians,
      summary.global_gaussians);
}

// The IMU samples dropped before use, when any were.
void PrintScreening(const ImuScreening& screening) {
  if (screening.beyond_range + screening.spikes == 0) return;
  std::printf(
      "imu: dropped %zu samples beyond the IMU's range (--imu-gyro-range, --imu-accel-range) and %zu "
      "isolated spikes\n",
      screening.beyond_range, screening.spikes);
}

// The window's last estimate: the tilt of the odometry's world against
// gravity, the biases, and its cost per scan.
void PrintInertial(const InertialMotion& inertial) {
  if (const std::optional<ImuFault>& fault = inertial.imu_fault()) {
    std::fprintf(stderr, "radargauss: warning: the IMU was dropped at %.2f s, the radar alone from there: %s\n",
                 fault->stamp, fault->cause.c_str());
  }
  const auto& states = inertial.states();
  if (inertial.imu_fault()) return;
  if (states.empty() || !states.back()) {
    std::printf("inertial: the window never started (no Doppler velocity)\n");
    return;
  }
  const InertialState& last = *states.back();
  const Eigen::Vector2d tilt = inertial.window().tilt() * (180.0 / M_PI);
  std::printf(
      "inertial: tilt roll %.3f pitch %.3f deg; gyro bias %.5f %.5f %.5f rad/s; accelerometer bias %.4f %.4f %.4f "
      "m/s^2\n",
      tilt.x(), tilt.y(), last.bias.gyro.x(), last.bias.gyro.y(), last.bias.gyro.z(), last.bias.accel.x(),
      last.bias.accel.y(), last.bias.accel.z());
  const RadarInertialOptions& o = inertial.options();
  const std::size_t held = std::size_t(std::count_if(inertial.solves().begin(), inertial.solves().end(),
                                                     [](const WindowSolveSummary& w) { return w.clock_offset_held; }));
  if (held > 0) {
    std::fprintf(stderr,
                 "radargauss: warning: the clock offset's estimate reached its bound (+-%g s, or the IMU's data) in "
                 "%zu of %zu solves and was held there: the clocks may disagree by more than a window calibrates\n",
                 kMaxClockOffset, held, inertial.solves().size());
  }
  if (o.window.estimate_clock_offset) {
    std::printf("inertial: clock offset estimated: %.2f ms (the IMU's stamps minus the radar's)\n",
                inertial.window().clock_offset() * 1e3);
  }
  if (o.window.estimate_extrinsic_rotation || o.window.estimate_extrinsic_translation) {
    const SE3d radar_from_imu = inertial.window().radar_from_imu();
    const Eigen::Vector3d angle = radar_from_imu.rotation().Log() * (180.0 / M_PI);
    const Eigen::Vector3d& t = radar_from_imu.translation();
    std::printf("inertial: T_radar_imu estimated: rotation vector %.3f %.3f %.3f deg, translation %.3f %.3f %.3f m\n",
                angle.x(), angle.y(), angle.z(), t.x(), t.y(), t.z());
  }
}

// The online calibration's estimates, one line per radar.
void PrintOnlineCalibration(const RigOnlineCalibration& calibration, const Rig& rig) {
  std::printf("online calibration: %zu windows\n", calibration.windows());
  for (std::size_t r = 1; r < calibration.radars(); ++r) {
    const SE3d moved = (rig.radars.front().body_from_radar.Inverse() * rig.radars[r].body_from_radar).Inverse() *
                       calibration.reference_from_radar(r);
    const RigOnlineCalibration::Vector7d std = calibration.std(r);
    const Eigen::Vector3i& observed = calibration.observed_directions(r);
    std::printf(
        "  %s: moved %.3f deg, %.3f m, clock %.1f ms; std (norm) %.3f deg, %.3f m, %.1f ms; observed directions: "
        "rotation %d of 3, "
        "translation %d of 3, clock %d of 1; %zu windows set aside\n",
        rig.radars[r].name.c_str(), moved.rotation().Log().norm() * 180.0 / M_PI, moved.translation().norm(),
        calibration.clock_change(r) * 1e3, std.head<3>().norm() * 180.0 / M_PI, std.segment<3>(3).norm(), std(6) * 1e3,
        observed(0), observed(1), observed(2), calibration.windows_set_aside(r));
  }
}

// The body's odometry from a rig's radars (docs/design/rig.md, "Odometry on a rig").
int RunRigOdometry(const OdometrySettings& s) {
  const OdometryOptions& options = s.odometry;
  ValidateOptions(options);
  if (!s.sequence.sequence_dir.empty() || !s.sequence.bag.empty()) {
    throw DataError("--rig names the radars' scans itself: drop --sequence and --bag");
  }
  if (!s.mcap.empty() || s.matcher != "gaussians") throw DataError("--rig: no --mcap, and no --matcher but gaussians");
  const Rig rig = ReadRig(s.rig);
  const ImuInput imu = RigImuOf(s, rig);  // before the run: a bad IMU leaves nothing behind
  std::optional<Trajectory> reference;
  if (!s.sequence.ground_truth.empty()) {
    reference =
        ReadRadarTrajectory(s.sequence.ground_truth, ResolveExtrinsic(s.sequence.extrinsic, s.sequence.ground_truth));
  }
  StagedFolder folder = RunFolder(s, {"odometry.tum", "body.tum", "levelled.tum", "map.rgm", "map.ply", "rig.yaml"});
  std::vector<SE3d> mountings;
  for (const RigRadar& radar : rig.radars) mountings.push_back(radar.body_from_radar);
  std::unique_ptr<MotionModel> motion =
      MakeRigMotionModel(imu.inertial, mountings.front(), imu.radar_from_imu, imu.samples);
  PrintScreening(motion->screening());
  RigOdometry odometry(mountings, options, std::move(motion));
  std::size_t scans = 0;
  ForEachRigScan(rig, [&](std::size_t radar, RadarScan& scan, const std::string& source) {
    try {
      odometry.Register(radar, scan);
    } catch (const DataError& e) {
      throw DataError(source + ": " + e.what());
    }
    ++scans;
  });
  odometry.Finish();
  const Trajectory body = odometry.trajectory();
  std::optional<Evaluation> evaluation;
  if (reference) evaluation = EvaluateTrajectory(body, *reference);
  WriteOdometry(folder.path(), odometry.odometry());
  WriteTum((std::filesystem::path(folder.path()) / "body.tum").string(), body);
  const std::string table = evaluation ? WriteEvaluation(folder.path(), *evaluation) : std::string();
  const RigOnlineCalibration* calibration = odometry.frames().online_calibration();
  if (calibration) {
    WriteRigWithAbsolutePaths((std::filesystem::path(folder.path()) / "rig.yaml").string(),
                              OnlineCalibratedRig(rig, odometry.frames()));
  }
  folder.Commit();
  std::printf("rig: %zu radars, %zu scans in %zu frames, %zu with their velocity measured (%zu by the rig's twist)",
              rig.radars.size(), scans, odometry.frame_radars().size(), odometry.velocity_measured(),
              odometry.rig_velocity_measured());
  if (!odometry.frame_times_ms().empty()) {
    std::vector<double> times = odometry.frame_times_ms();
    std::sort(times.begin(), times.end());
    std::printf("; %.2f ms per frame (median, p90 %.2f)", MedianOfSorted(times), PercentileOfSorted(times, 0.9));
  }
  std::printf("\n");
  if (calibration) PrintOnlineCalibration(*calibration, rig);
  PrintSummary(Summarise(odometry.odometry()));
  const InertialMotion* inertial = InertialMotionOf(odometry.odometry());
  if (inertial) PrintInertial(*inertial);
  std::printf("%s", table.c_str());
  std::printf(
      "wrote %s (body.tum: T_world_body; odometry.tum, per_scan.csv and summary.json of the %s odometry%s%s%s%s)\n",
      s.out.c_str(), rig.radars.size() == 1 ? "radar's" : "body's",
      options.map.keep_evicted ? ", map.rgm, map.ply" : "", inertial ? ", inertial.csv" : "",
      evaluation ? ", evaluation.json, evaluation.md" : "", calibration ? ", rig.yaml: the rig calibrated online" : "");
  return 0;
}

int RunOdometry(const OdometrySettings& s) {
  if (!s.rig.empty()) return RunRigOdometry(s);
  const OdometryOptions& options = s.odometry;
  ValidateOptions(options);
  ImuRotation(s.imu_rotation);
  RunInputs inputs = LoadRunInputs(s, options.match.matching.w_rcs);
  const Sequence& sequence = inputs.sequence;
  const std::optional<Trajectory>& reference = inputs.reference;
  StagedFolder folder = RunFolder(s, {"odometry.tum", "levelled.tum", "map.rgm", "map.ply"});  // before the run
  const ImuInput imu = ImuOf(s);  // before the run: a bad IMU leaves nothing behind
  if (!imu.samples.empty()) CheckOverlap(imu.samples, sequence, s.imu_topic.empty() ? "" : "; try --imu-stamps record");
  std::unique_ptr<MotionModel> motion = MakeMotionModel(imu.inertial, imu.radar_from_imu, imu.samples);
  if (motion->name() == "window" && s.matcher != "gaussians") {
    throw DataError("--imu-fusion window needs --matcher gaussians");
  }
  PrintScreening(motion->screening());
  RadarOdometry odometry(options, std::move(motion), MatcherOf(s.matcher));
  RegisterScans(sequence, "odometry", [&](const RadarScan& scan) { odometry.Register(scan); });
  const InertialMotion* inertial = InertialMotionOf(odometry);
  std::optional<Evaluation> evaluation;
  if (reference) evaluation = EvaluateTrajectory(odometry.trajectory(), *reference);
  WriteOdometry(folder.path(), odometry);
  const std::string table = evaluation ? WriteEvaluation(folder.path(), *evaluation) : std::string();
  folder.Commit();
  if (!s.mcap.empty()) WriteRunForViewer(s.out, sequence.scans, reference, s.mcap);
  PrintSummary(Summarise(odometry));
  const std::optional<Mounting> mounting = EstimateMounting(odometry.steps());
  if (mounting) {
    const Trajectory levelled = Levelled(odometry.trajectory(), *mounting);
    std::printf("mounting: pitch %.2f deg (%zu scans), yaw %.2f deg (%zu straight); end height %.2f m levelled\n",
                mounting->pitch_deg, mounting->pitch_scans, mounting->yaw_deg, mounting->yaw_scans,
                levelled[levelled.size() - 1].pose.translation().z());
  }
  if (inertial) PrintInertial(*inertial);
  std::printf("%s", table.c_str());
  std::printf("wrote %s (odometry.tum, %sper_scan.csv, summary.json%s%s%s)\n", s.out.c_str(),
              mounting ? "levelled.tum, " : "", s.odometry.map.keep_evicted ? ", map.rgm, map.ply" : "",
              inertial ? ", inertial.csv" : "", evaluation ? ", evaluation.json, evaluation.md" : "");
  return 0;
}

}  // namespace

Subcommand AddOdometry(CLI::App& parent) {
  auto s = std::make_shared<OdometrySettings>();
  CLI::App* app = parent.add_subcommand("odometry", "Radar odometry on a Gaussian-RCS map built on the way");
  AddSequenceOptions(app, s->sequence, "--gt",
                     "Reference trajectory (TUM, or BAG:/topic[:child] of a ROS 2 bag), for the evaluation only");
  app->add_option("--out", s->out, "Output folder")->required();
  AddOdometryOptions(app, *s);
  app->add_option("--rig", s->rig,
                  "Rig file (docs/design/rig.md): the body's odometry from every radar's scans instead of --sequence "
                  "(--gt: the body's reference)");
  return {app, [s] { return RunOdometry(*s); }};
}

}  // namespace radargauss::cli
