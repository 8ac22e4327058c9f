// SPDX-License-Identifier: BSD-3-Clause
// radargauss localize: the paper's localisation experiment (docs/design/experiment.md,
// "The localisation experiment"): every scan matched from its reference
// pose plus a seeded error, for every combination of the swept settings.
#include <zlib.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.hpp"
#include "localize_settings.hpp"
#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/experiment/experiment.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/map_tiles.hpp"
#include "radargauss/core/progress.hpp"
#include "radargauss/solvers/factory.hpp"
#ifdef RADARGAUSS_HAVE_PCL
#include "radargauss/peers/pcl_peers.hpp"
#endif

namespace radargauss::cli {

namespace {

// The maps to match against: the map file, or one per (incidence, degree)
// built here; `degrees` receives each map's degree.
std::vector<GaussianMap> MapsToMatch(const Sequence& sequence, LocalizeSettings& s, std::vector<int>& degrees) {
  std::vector<GaussianMap> maps;
  if (!s.map_path.empty()) {
    if (!s.incidences.empty() || !s.degrees.empty()) {
      throw DataError("--incidences/--degrees need the map built here (drop --map)");
    }
    maps.push_back(ReadMapOrTiles(s.map_path));
    degrees = {s.build.map.rcs.max_degree};
    return maps;
  }
  if (s.incidences.empty()) s.incidences = {ToString(s.build.map.rcs.incidence)};
  if (s.degrees.empty()) s.degrees = {s.build.map.rcs.max_degree};
  const MapGeometry geometry = BuildGeometry(sequence, s.build, false);
  std::printf("map: %zu Gaussians from %zu static points\n", geometry.map.gaussians.size(),
              geometry.cloud.points.size());
  for (const std::string& incidence : s.incidences) {
    for (const int degree : s.degrees) {
      maps.push_back(FitRcsModelsOf(geometry, s.build, IncidenceModelFromString(incidence), degree, true));
      degrees.push_back(degree);
    }
  }
  return maps;
}

// The matched scans (every stride-th; with --shard, the shard's part of
// them), their references and initial errors.
struct Experiment {
  std::vector<RadarScan> scans;
  std::vector<SE3d> references;
  std::vector<SE3d> errors;
  std::size_t first_scan = 0;   // of the shard, in the experiment's numbering
  std::size_t total_scans = 0;  // of the whole experiment
};

Experiment MakeExperiment(const Sequence& sequence, const LocalizeSettings& s) {
  Experiment e;
  for (std::size_t k = 0; k < sequence.scans.size(); k += std::size_t(s.stride)) {
    e.scans.push_back(sequence.scans[k]);
    e.references.push_back(sequence.poses[k]);
  }
  e.errors = InitialErrors(e.scans.size(), s.max_translation, s.max_rotation, s.seed);
  e.total_scans = e.scans.size();
  if (!s.shard.empty()) {  // the errors of the whole experiment, then the shard's part
    const Shard shard = ParseShard(s.shard);
    const std::size_t begin = shard.Begin(e.total_scans), end = shard.End(e.total_scans);
    if (begin == end) throw DataError("shard " + s.shard + " of " + std::to_string(e.total_scans) + " scans is empty");
    e.scans = std::vector<RadarScan>(e.scans.begin() + begin, e.scans.begin() + end);
    e.references = std::vector<SE3d>(e.references.begin() + begin, e.references.begin() + end);
    e.errors = std::vector<SE3d>(e.errors.begin() + begin, e.errors.begin() + end);
    e.first_scan = begin;
  }
  return e;
}

// The PCL peers' row: the merged map cloud as the target (no w_rcs, no loss).
ConfigurationRun RunPeer(const std::string& solver, const Sequence& sequence, const LocalizeSettings& s,
                         const MatchingMap& matching, const Experiment& e, std::vector<Eigen::Vector3d>& map_cloud) {
#ifdef RADARGAUSS_HAVE_PCL
  if (map_cloud.empty()) map_cloud = BuildMapCloud(sequence).points;
  PclPeerOptions options;
  options.ndt_resolution = s.ndt_resolution;
  options.ndt_step_size = s.ndt_step;
  const PclPeerMatcher peer(solver == "pcl-ndt" ? PclMethod::kNdt : PclMethod::kGicp, map_cloud, options);
  return RunConfiguration(solver, 0.0, peer, matching, e.scans, e.references, e.errors, e.first_scan);
#else
  (void)sequence, (void)s, (void)matching, (void)e, (void)map_cloud;
  throw DataError("solver '" + solver + "' needs radargauss built with RADARGAUSS_WITH_PCL");
#endif
}

std::vector<ConfigurationRun> RunConfigurations(const Sequence& sequence, const LocalizeSettings& s,
                                                const std::vector<GaussianMap>& maps, const std::vector<int>& degrees,
                                                const Experiment& e) {
  std::vector<ConfigurationRun> runs;
  std::vector<Eigen::Vector3d> map_cloud;  // the PCL peers' target
  ProgressBar bar;
  const std::size_t total = maps.size() * s.solvers.size() * s.losses.size() * (s.w_rcs.size() + s.w_rcs_from_map);
  std::size_t done = 0;
  for (std::size_t m = 0; m < maps.size(); ++m) {
    const MatchingMap matching(maps[m], s.matching_map);
    const std::vector<std::pair<double, bool>> weights = s.Weights(maps[m]);
    for (const std::string& solver : s.solvers) {
      if (solver.rfind("pcl-", 0) == 0) {
        if (m > 0) continue;  // the peers do not use the RCS models: once
        bar.Update("localize", done, total);
        runs.push_back(RunPeer(solver, sequence, s, matching, e, map_cloud));
        ++done;
        continue;
      }
      for (const std::string& loss : s.losses) {
        for (const auto& [w, from_map] : weights) {
          const auto matcher = MakeScanMatcher(s.Configuration(solver, w, loss));
          const std::string name = solver + (from_map ? "-wmap" : "-w") + FormatWeight(w) + "-" + loss + "-" +
                                   ToString(maps[m].incidence) + "-L" + std::to_string(degrees[m]);
          bar.Update("localize", done, total);
          runs.push_back(RunConfiguration(name, w, *matcher, matching, e.scans, e.references, e.errors, e.first_scan));
          ++done;
        }
      }
    }
  }
  bar.Update("localize", done, total);
  bar.Finish();
  return runs;
}

// The outputs beside the experiment's: the reference trajectory and the
// map's Gaussian means, for the plots.
void WritePlotInputs(const std::string& out, const Experiment& e, const GaussianMap& map) {
  std::vector<double> times;
  for (const RadarScan& scan : e.scans) times.push_back(scan.timestamp);
  WriteReferenceTrajectory(out, times, e.references);
  namespace fs = std::filesystem;
  WriteFileAtomically((fs::path(out) / "map_means.csv").string(), [&](std::ostream& stream) {
    stream << "x,y,z\n";
    for (const Gaussian& g : map.gaussians) {
      stream << g.mean.x() << ',' << g.mean.y() << ',' << g.mean.z() << '\n';
    }
  });
}

// CRC-32 of doubles, as their bytes.
std::uint32_t Checksum(std::uint32_t crc, const double* values, std::size_t n) {
  return std::uint32_t(crc32(crc, reinterpret_cast<const Bytef*>(values), uInt(n * sizeof(double))));
}

std::string Hex(std::uint32_t value) {
  char text[9];
  std::snprintf(text, sizeof(text), "%08x", value);
  return text;
}

// What makes shards parts of one experiment (docs/design/experiment.md, "Shards"): the
// value of every flag that changes results, and the contents behind the
// paths (scans, reference poses, the maps matched) rather than their
// spelling, so workers may mount the data elsewhere.
ExperimentIdentity IdentityOf(const CLI::App& app, const Sequence& sequence, const std::vector<GaussianMap>& maps) {
  ExperimentIdentity identity;
  const std::vector<std::string> skipped = {"--help", "--out", "--shard", "--sequence",
                                            "--gt",   "--map", "--bag",   "--extrinsic"};
  for (const CLI::Option* option : app.get_options()) {
    const std::string name = option->get_name();
    if (std::find(skipped.begin(), skipped.end(), name) != skipped.end()) continue;
    identity.emplace_back(name,
                          option->count() > 0 ? CLI::detail::join(option->results(), ",") : option->get_default_str());
  }
  std::uint32_t scans = 0, poses = 0;
  for (std::size_t k = 0; k < sequence.scans.size(); ++k) {
    scans = Checksum(scans, &sequence.scans[k].timestamp, 1);
    for (const RadarPoint& p : sequence.scans[k].points) {
      const double values[5] = {p.position.x(), p.position.y(), p.position.z(), p.doppler, p.rcs};
      scans = Checksum(scans, values, 5);
    }
    const Eigen::Quaterniond& q = sequence.poses[k].rotation().quaternion();
    const Eigen::Vector3d& t = sequence.poses[k].translation();
    const double pose[7] = {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
    poses = Checksum(poses, pose, 7);
  }
  identity.emplace_back("scans", std::to_string(sequence.scans.size()) + " scans, crc32 " + Hex(scans));
  identity.emplace_back("reference poses", "crc32 " + Hex(poses));
  std::uint32_t gaussians = 0;
  std::size_t count = 0;
  for (const GaussianMap& map : maps) {
    for (const Gaussian& g : map.gaussians) {
      gaussians = Checksum(gaussians, g.mean.data(), 3);
      gaussians = Checksum(gaussians, g.covariance.data(), 9);
      const double rcs[2] = {g.rcs.median, g.rcs.scale};
      gaussians = Checksum(gaussians, rcs, 2);
      gaussians = Checksum(gaussians, g.rcs.coefficients.data(), g.rcs.coefficients.size());
    }
    count += map.gaussians.size();
  }
  identity.emplace_back("maps", std::to_string(count) + " Gaussians, crc32 " + Hex(gaussians));
  return identity;
}

int RunLocalize(LocalizeSettings s, const CLI::App& app) {
  const Sequence sequence = LoadSequence(s.CheckedSequenceOptions());
  s.CheckAgainst(sequence);
  std::vector<int> degrees;
  const std::vector<GaussianMap> maps = MapsToMatch(sequence, s, degrees);
  const Experiment e = MakeExperiment(sequence, s);
  StagedFolder folder(s.out);  // a bad --out fails before the run
  const std::vector<ConfigurationRun> runs = RunConfigurations(sequence, s, maps, degrees, e);
  const std::string table = WriteExperimentResults(folder.path(), runs);
  WritePlotInputs(folder.path(), e, maps.front());
  if (!s.shard.empty()) {
    WriteShard(folder.path(), ParseShard(s.shard), e.total_scans, IdentityOf(app, sequence, maps), runs, e.references);
  }
  folder.Commit();
  double initial_t = 0.0;
  for (const ScanOutcome& o : runs.front().outcomes) initial_t += o.initial_translation_error;
  std::printf("%zu scans, %zu configurations; initial errors: mean %.3f m (uniform in [0, %g] m, [0, %g] deg)\n\n%s\n",
              e.scans.size(), runs.size(), initial_t / std::max<std::size_t>(1, e.scans.size()), s.max_translation,
              s.max_rotation, table.c_str());
  std::printf(
      "results: %s (per_scan.csv, summary.json, table.md, trajectories/); plots: "
      "scripts/plot_results.py %s --reference %s/reference.tum\n",
      s.out.c_str(), s.out.c_str(), s.out.c_str());
  return 0;
}

}  // namespace

void WriteReferenceTrajectory(const std::string& out, const std::vector<double>& times,
                              const std::vector<SE3d>& references) {
  Trajectory reference;
  for (std::size_t k = 0; k < times.size(); ++k) {
    if (reference.empty() || times[k] > reference.EndTime()) reference.Append(times[k], references[k]);
  }
  WriteTum((std::filesystem::path(out) / "reference.tum").string(), reference);
}

Subcommand AddLocalize(CLI::App& parent) {
  auto s = std::make_shared<LocalizeSettings>();
  CLI::App* app = parent.add_subcommand("localize", "The paper's localisation experiment (w_rcs sweep)");
  AddLocalizeOptions(app, *s);
  return {app, [s, app] { return RunLocalize(*s, *app); }};
}

}  // namespace radargauss::cli
