// SPDX-License-Identifier: BSD-3-Clause
// radargauss relocalize: a sequence located in a SLAM map without an initial
// pose (docs/design/slam.md, "Relocalisation"), evaluated against a reference
// when one is given.
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "option_flags.hpp"
#include "odometry_settings.hpp"
#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/experiment/evaluation.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/map_tiles.hpp"
#include "radargauss/io/rig.hpp"
#include "radargauss/odometry/rig_odometry.hpp"
#include "radargauss/core/progress.hpp"
#include "radargauss/residuals/rcs_likelihood.hpp"
#include "radargauss/slam/relocalization.hpp"

namespace radargauss::cli {

namespace {

struct RelocalizeSettings {
  OdometrySettings odometry;
  std::string map;
  RelocalizationOptions relocalization;
  bool w_rcs_from_map = false;  // w_rcs chosen from the map's RCS fits (RcsWeightFromMap)
};

void WritePerScan(std::ostream& out, const Relocalizer& relocalizer) {
  out << "scan,stamp,fixed,matched,x,y,z,qx,qy,qz,qw,reason\n" << std::setprecision(9);
  for (std::size_t k = 0; k < relocalizer.steps().size(); ++k) {
    const RelocalizationStep& s = relocalizer.steps()[k];
    const Eigen::Quaterniond& q = s.pose.rotation().quaternion();
    const Eigen::Vector3d& t = s.pose.translation();
    out << k << ',' << std::fixed << s.stamp << std::defaultfloat << ',' << s.fixed << ',' << s.matched;
    if (s.fixed) {
      out << ',' << t.x() << ',' << t.y() << ',' << t.z() << ',' << q.x() << ',' << q.y() << ',' << q.z() << ','
          << q.w();
    } else {
      out << ",,,,,,,";
    }
    out << ",\"" << s.reason << "\"\n";
  }
}

void WriteCandidates(std::ostream& out, const Relocalizer& relocalizer) {
  out << "submap,place,score,yaw_deg,verified,overlap,associated,cost,translation_std,rotation_std_deg,accepted,"
         "fixed,reason\n"
      << std::setprecision(6);
  for (const PlaceCandidate& c : relocalizer.candidates()) {
    out << c.submap << ',' << c.place << ',' << c.distance << ',' << c.yaw * 180.0 / M_PI << ',' << c.verified << ','
        << c.check.overlap << ',' << c.check.associated << ',' << c.check.cost << ',' << c.check.translation_std << ','
        << c.check.rotation_std_deg << ',' << c.check.accepted << ',' << c.fixed << ",\"" << c.check.reason << "\"\n";
  }
}

// A rig's frames into the relocaliser, on the body's clock; the scans read.
std::size_t RelocalizeRig(const Rig& rig, const RelocalizationOptions& options, Relocalizer& relocalizer) {
  const RadarOdometry* odometry = nullptr;
  bool fixed = false;
  return RegisterRigFrames(rig, options.odometry, [&](const RigFrame& frame) {
    relocalizer.Register(frame.scan, frame.velocity);
    // A fix or a restart moves the odometry's poses.
    const bool jumped = &relocalizer.odometry() != odometry || relocalizer.fixed() != fixed;
    odometry = &relocalizer.odometry();
    fixed = relocalizer.fixed();
    return RegisteredFrame{odometry->pose(odometry->scans() - 1), jumped};
  });
}

nlohmann::json Summary(const Relocalizer& relocalizer, std::size_t located, std::size_t matched) {
  const std::optional<std::size_t> fix = relocalizer.first_fix();
  const std::vector<RelocalizationStep>& steps = relocalizer.steps();
  nlohmann::json summary = {
      {"scans", steps.size()},
      {"fixed_scans", located},
      {"matched_scans", matched},
      {"submaps_compared", relocalizer.candidates().empty() ? 0 : relocalizer.candidates().back().submap + 1}};
  summary["first_fix_scan"] = fix ? nlohmann::json(*fix) : nlohmann::json(nullptr);
  summary["time_to_first_fix_s"] =
      fix ? nlohmann::json(steps[*fix].stamp - steps.front().stamp) : nlohmann::json(nullptr);
  return summary;
}

int RunRelocalize(const RelocalizeSettings& s) {
  RelocalizationOptions options = s.relocalization;
  ValidateOptions(options);
  GaussianMap map = ReadMapOrTiles(s.map);
  ScanMatchingOptions& matching = options.odometry.match.matching;
  if (s.w_rcs_from_map) {
    matching.w_rcs = RcsWeightFromMap(SummariseRcs(map, matching.rcs_terms));
    std::printf("relocalize: w_rcs %.3f from the map's RCS fits\n", matching.w_rcs);
  }
  if (map.places.empty()) {
    throw FileError(s.map, "the map has no places to relocalise against (build it with radargauss slam)");
  }
  if (map.gaussians.empty()) throw FileError(s.map, "the map has no Gaussians to match against");
  const bool on_rig = !s.odometry.rig.empty();
  if (on_rig && (!s.odometry.sequence.sequence_dir.empty() || !s.odometry.sequence.bag.empty())) {
    throw DataError("--rig names the radars' scans itself: drop --sequence and --bag");
  }
  if (on_rig && !s.odometry.mcap.empty()) throw DataError("--rig: no --mcap");
  const std::optional<Rig> rig = on_rig ? std::optional<Rig>(ReadRig(s.odometry.rig)) : std::nullopt;
  if (rig) options.odometry = ReferenceRadarOptions(options.odometry, rig->radars.front().body_from_radar);
  RunInputs inputs;
  if (!on_rig) {
    inputs = LoadRunInputs(s.odometry, matching.w_rcs);
  } else if (!s.odometry.sequence.ground_truth.empty()) {
    inputs.reference =
        ReadRadarTrajectory(s.odometry.sequence.ground_truth,
                            ResolveExtrinsic(s.odometry.sequence.extrinsic, s.odometry.sequence.ground_truth));
  }
  const Sequence& sequence = inputs.sequence;
  const std::optional<Trajectory>& reference = inputs.reference;
  StagedFolder folder = RunFolder(s.odometry, {"relocalization.tum", "body.tum"});
  Relocalizer relocalizer(std::move(map), options);
  std::size_t scans = sequence.scans.size();
  if (rig) {
    scans = RelocalizeRig(*rig, options, relocalizer);
  } else {
    RegisterScans(sequence, "relocalize", [&](const RadarScan& scan) { relocalizer.Register(scan); });
  }
  Trajectory located;
  std::size_t matched = 0;
  for (const RelocalizationStep& step : relocalizer.steps()) {
    if (step.fixed) located.Append(step.stamp, step.pose);
    matched += step.matched;
  }
  // On a rig: the body's poses beside the reference radar's, and the evaluation of the body's.
  const Trajectory evaluated = rig ? BodyTrajectory(located, rig->radars.front().body_from_radar) : located;
  const std::filesystem::path out(folder.path());
  WriteTum((out / "relocalization.tum").string(), located);
  if (rig) WriteTum((out / "body.tum").string(), evaluated);
  WriteFileAtomically((out / "per_scan.csv").string(), [&](std::ostream& o) { WritePerScan(o, relocalizer); });
  WriteFileAtomically((out / "candidates.csv").string(), [&](std::ostream& o) { WriteCandidates(o, relocalizer); });
  const std::optional<std::size_t> fix = relocalizer.first_fix();
  const double first_stamp = relocalizer.steps().empty() ? 0.0 : relocalizer.steps().front().stamp;
  WriteFileAtomically((out / "summary.json").string(),
                      [&](std::ostream& o) { o << Summary(relocalizer, located.size(), matched).dump(2) << "\n"; });
  std::string table;
  if (reference && located.size() >= 3)
    table = WriteEvaluation(out.string(), EvaluateTrajectory(evaluated, *reference));
  folder.Commit();
  if (!s.odometry.mcap.empty()) WriteRunForViewer(s.odometry.out, sequence.scans, reference, s.odometry.mcap);
  if (fix) {
    std::printf("relocalize: first fix at %s %zu (%.1f s in); %zu of %zu %s located, %zu matched to the map\n",
                rig ? "frame" : "scan", *fix, relocalizer.steps()[*fix].stamp - first_stamp, located.size(),
                relocalizer.steps().size(), rig ? "frames" : "scans", matched);
  } else {
    std::printf("relocalize: no fix: none of the %zu candidates of %d submaps verified; no pose reported\n",
                relocalizer.candidates().size(),
                relocalizer.candidates().empty() ? 0 : relocalizer.candidates().back().submap + 1);
  }
  std::printf("%s", table.c_str());
  if (rig)
    std::printf("rig: %zu radars, %zu scans in %zu frames\n", rig->radars.size(), scans, relocalizer.steps().size());
  std::printf("wrote %s (relocalization.tum%s, per_scan.csv, candidates.csv, summary.json%s)\n", s.odometry.out.c_str(),
              rig ? ", body.tum" : "", table.empty() ? "" : ", evaluation.json, evaluation.md");
  return 0;
}

}  // namespace

Subcommand AddRelocalize(CLI::App& parent) {
  auto s = std::make_shared<RelocalizeSettings>();
  CLI::App* app =
      parent.add_subcommand("relocalize", "Locate a sequence (or a rig: --rig) in a SLAM map without an initial pose");
  app->add_option("--map", s->map, "Map of radargauss slam (.rgm with places, or its folder of map tiles)")->required();
  AddSequenceOptions(app, s->odometry.sequence, "--gt",
                     "Reference trajectory (TUM, map frame), for the evaluation only");
  app->add_option("--out", s->odometry.out, "Output folder")->required();
  AddTableOptions(app, RelocalizationOptionTable(), s->relocalization, OdometryListedElsewhere());
  AddBoolFlag(app, "--w-rcs-from-map", s->w_rcs_from_map,
              "Eq. 2's w_rcs chosen from the map's RCS fits instead of --w-rcs (docs/design.md)")
      ->excludes(app->get_option("--w-rcs"))
      ->group(HelpGroup(OptionGroup::kTuning));
  AddRunOptions(app, s->odometry);
  app->add_option("--rig", s->odometry.rig,
                  "Rig file (docs/design/rig.md): relocalise the body from every radar's scans instead of --sequence, "
                  "in a map of slam --rig (--gt: the body's reference)")
      ->group(HelpGroup(OptionGroup::kTuning));  // --help-all; the command's description names it
  return {app, [s] { return RunRelocalize(*s); }};
}

}  // namespace radargauss::cli
