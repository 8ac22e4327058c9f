// SPDX-License-Identifier: BSD-3-Clause
// radargauss export: a results folder as an MCAP file a robotics viewer opens.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/rig.hpp"
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
  std::string rig;           // --rig: the scans of a rig's radars instead of --sequence
};

// A rig's scans as its run's frames (docs/design/rig.md, "The rig file"): each
// scan, on the body's clock, joins the first pose at or after its stamp
// (the frame that registered it), its points moved through its mounting
// and by the run's motion between: T_map_ref(t_f)^-1 T_map_ref(t_k) T_ref_radar
// (the run's poses are the reference radar's). Scans outside the run's span
// take their frame's pose.
std::vector<RadarScan> RigFramesOfRun(const Rig& rig, const RunForViewer& run) {
  Trajectory trajectory;
  for (std::size_t k = 0; k < run.stamps.size(); ++k) trajectory.Append(run.stamps[k], run.poses[k]);
  std::vector<RadarScan> frames(run.stamps.size());
  for (std::size_t k = 0; k < frames.size(); ++k) frames[k].timestamp = run.stamps[k];
  if (frames.empty()) return frames;
  std::vector<bool> doppler(frames.size(), true), rcs(frames.size(), true);
  const SE3d reference_from_body = rig.radars.front().body_from_radar.Inverse();
  const std::vector<std::vector<RadarScan>> scans = LoadRigScans(rig);
  for (std::size_t r = 0; r < rig.radars.size(); ++r) {
    const SE3d reference_from_radar = reference_from_body * rig.radars[r].body_from_radar;
    for (const RadarScan& scan : scans[r]) {
      const double stamp = scan.timestamp - rig.radars[r].clock_offset;
      const auto at = std::lower_bound(run.stamps.begin(), run.stamps.end(), stamp - 1e-6);
      if (at == run.stamps.end()) continue;  // after the run's last frame
      const std::size_t f = std::size_t(at - run.stamps.begin());
      const std::optional<SE3d> then = trajectory.Interpolate(stamp);
      const SE3d frame_from_radar = (then ? run.poses[f].Inverse() * *then : SE3d()) * reference_from_radar;
      for (RadarPoint point : scan.points) {
        point.position = frame_from_radar * point.position;
        frames[f].points.push_back(point);
      }
      doppler[f] = doppler[f] && scan.has_doppler;
      rcs[f] = rcs[f] && scan.has_rcs;
    }
  }
  for (std::size_t k = 0; k < frames.size(); ++k) {
    frames[k].has_doppler = doppler[k];
    frames[k].has_rcs = rcs[k];
  }
  return frames;
}

// --rig: the rig's frames beside the run's poses, and the body's --gt as the reference radar's.
int RunRigExport(const ExportSettings& s) {
  if (!s.sequence.sequence_dir.empty() || !s.sequence.bag.empty()) {
    throw DataError("--rig names the radars' scans itself: drop --sequence and --bag");
  }
  const Rig rig = ReadRig(s.rig);
  const std::vector<RadarScan> frames = RigFramesOfRun(rig, ReadRunFolder(s.run));
  std::optional<Trajectory> reference;  // T_world_ref = T_world_body T_body_ref
  if (!s.sequence.ground_truth.empty()) {
    reference = ReadRadarTrajectory(s.sequence.ground_truth, rig.radars.front().body_from_radar);
  }
  WriteRunForViewer(s.run, frames, reference, s.mcap);
  std::printf("wrote %s (the frames of %zu radars in the reference radar's frame)\n", s.mcap.c_str(),
              rig.radars.size());
  return 0;
}

int RunExport(const ExportSettings& s) {
  if (!s.rig.empty()) return RunRigExport(s);
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
  AddSequenceOptions(app, s->sequence, "--gt",
                     "Reference trajectory (TUM; with --rig, the body's), shown aligned at the first pose");
  app->add_option("--rig", s->rig,
                  "Rig file (docs/design/rig.md) of the run (odometry, slam or relocalize --rig): every radar's "
                  "scans as the run's frames instead of --sequence");
  return {app, [s] { return RunExport(*s); }};
}

}  // namespace radargauss::cli
