// SPDX-License-Identifier: BSD-3-Clause
// radargauss export: a results folder as an MCAP file a robotics viewer opens.
#include <cmath>
#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/experiment/run_mcap.hpp"

namespace radargauss::cli {

void WriteRunForViewer(const std::string& run_folder, const std::vector<RadarScan>& scans,
                       const std::optional<Trajectory>& reference, const std::string& mcap) {
  RunForViewer run = ReadRunFolder(run_folder);
  // Stamps ROS cannot hold, named before the file is begun.
  for (const double stamp : run.stamps) {
    if (!FitsRosTime(stamp))
      throw FileError(run_folder,
                      "its trajectory's stamp " + std::to_string(stamp) + " s does not fit ROS's time (0 to 2^31 s)");
  }
  for (std::size_t k = 0; reference && k < reference->size(); ++k) {
    const double stamp = (*reference)[k].time;
    if (!FitsRosTime(stamp)) throw DataError("--gt: stamp " + std::to_string(stamp) + " s does not fit ROS's time");
  }
  if (!scans.empty()) {
    // Each pose's scan by stamp (the TUM file holds 9 decimals); a pose without one shows none.
    std::size_t next = 0;
    for (const double stamp : run.stamps) {
      while (next < scans.size() && scans[next].timestamp < stamp - 1e-6) ++next;
      RadarScan scan;
      scan.timestamp = stamp;
      if (next < scans.size() && std::abs(scans[next].timestamp - stamp) <= 1e-6) scan = scans[next];
      run.scans.push_back(scan);
    }
  }
  if (reference && !reference->empty() && !run.poses.empty()) {
    const std::optional<SE3d> at_first = reference->Interpolate(run.stamps.front());
    const SE3d align = at_first ? run.poses.front() * at_first->Inverse() : SE3d();
    for (const StampedPose& p : *reference) {
      run.reference_stamps.push_back(p.time);
      run.reference.push_back(align * p.pose);
    }
  }
  WriteRunMcap(mcap, run);
}

namespace {

struct ExportSettings {
  std::string run;
  std::string mcap;
  SequenceOptions sequence;  // the scans and (--gt) the reference, both optional
};

int RunExport(const ExportSettings& s) {
  std::vector<RadarScan> scans;
  if (!s.sequence.sequence_dir.empty() || !s.sequence.bag.empty()) {
    SequenceOptions scans_only = s.sequence;
    scans_only.ground_truth.clear();
    scans = LoadSequence(scans_only).scans;
  }
  std::optional<Trajectory> reference;
  if (!s.sequence.ground_truth.empty()) {
    reference =
        ReadRadarTrajectory(s.sequence.ground_truth, ResolveExtrinsic(s.sequence.extrinsic, s.sequence.ground_truth));
  }
  WriteRunForViewer(s.run, scans, reference, s.mcap);
  std::printf("wrote %s\n", s.mcap.c_str());
  return 0;
}

}  // namespace

Subcommand AddExport(CLI::App& parent) {
  auto s = std::make_shared<ExportSettings>();
  CLI::App* app = parent.add_subcommand(
      "export", "Write a results folder (odometry, slam, relocalize) as an MCAP file a robotics viewer opens");
  app->add_option("run", s->run, "The results folder")->required();
  app->add_option("--mcap", s->mcap, "The MCAP file to write")->required();
  AddSequenceOptions(app, s->sequence, "--gt", "Reference trajectory (TUM), shown aligned at the first pose");
  return {app, [s] { return RunExport(*s); }};
}

}  // namespace radargauss::cli
