// SPDX-License-Identifier: BSD-3-Clause
// radargauss odometry: radar odometry on a map the run builds itself
// (docs/design.md, "Odometry"), evaluated against a reference when one is given.
#include <cstdio>
#include <memory>
#include <optional>

#include "commands.hpp"
#include "odometry_settings.hpp"
#include "radargauss/atomic_file.hpp"
#include "radargauss/error.hpp"
#include "radargauss/evaluation.hpp"
#include "radargauss/odometry/mounting.hpp"
#include "radargauss/progress.hpp"

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

int RunOdometry(const OdometrySettings& s) {
  const OdometryOptions& options = s.odometry;
  ValidateOptions(options);
  ImuRotation(s.imu_rotation);
  RunInputs inputs = LoadRunInputs(s, options.match.matching.w_rcs);
  const Sequence& sequence = inputs.sequence;
  const std::optional<Trajectory>& reference = inputs.reference;
  StagedFolder folder = RunFolder(s, {"odometry.tum", "levelled.tum", "map.rgm", "map.ply"});  // before the run
  RadarOdometry odometry(options, MatcherOf(s.matcher));
  const std::vector<GyroSample> gyro = GyroOf(s);  // before the run: a bad IMU leaves nothing behind
  if (!gyro.empty()) {
    CheckOverlap(gyro, sequence, s.imu_topic.empty() ? "" : "; try --imu-stamps record");
    odometry.AddGyro(gyro);
  }
  RegisterScans(sequence, "odometry", [&](const RadarScan& scan) { odometry.Register(scan); });
  std::optional<Evaluation> evaluation;
  if (reference) evaluation = EvaluateTrajectory(odometry.trajectory(), *reference);
  WriteOdometry(folder.path(), odometry);
  const std::string table = evaluation ? WriteEvaluation(folder.path(), *evaluation) : std::string();
  folder.Commit();
  PrintSummary(Summarise(odometry));
  const std::optional<Mounting> mounting = EstimateMounting(odometry.steps());
  if (mounting) {
    const Trajectory levelled = Levelled(odometry.trajectory(), *mounting);
    std::printf("mounting: pitch %.2f deg (%zu scans), yaw %.2f deg (%zu straight); end height %.2f m levelled\n",
                mounting->pitch_deg, mounting->pitch_scans, mounting->yaw_deg, mounting->yaw_scans,
                levelled[levelled.size() - 1].pose.translation().z());
  }
  std::printf("%s", table.c_str());
  std::printf("wrote %s (odometry.tum, %sper_scan.csv, summary.json, map.rgm, map.ply%s)\n", s.out.c_str(),
              mounting ? "levelled.tum, " : "", evaluation ? ", evaluation.json, evaluation.md" : "");
  return 0;
}

}  // namespace

Subcommand AddOdometry(CLI::App& parent) {
  auto s = std::make_shared<OdometrySettings>();
  CLI::App* app = parent.add_subcommand("odometry", "Radar odometry on a Gaussian-RCS map built on the way");
  AddSequenceOptions(app, s->sequence, "--gt", "Reference trajectory (TUM), for the evaluation only");
  app->add_option("--out", s->out, "Output folder")->required();
  AddOdometryOptions(app, *s);
  return {app, [s] { return RunOdometry(*s); }};
}

}  // namespace radargauss::cli
