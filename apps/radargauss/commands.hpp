// SPDX-License-Identifier: BSD-3-Clause
// The subcommands of the radargauss tool, one file each. A subcommand adds
// its flags to the parser and returns what runs it once parsing succeeded.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "radargauss/io/rig.hpp"
#include "radargauss/io/sequence.hpp"
#include "radargauss/map/pipeline.hpp"

namespace radargauss::cli {

struct Subcommand {
  CLI::App* app = nullptr;
  std::function<int()> run;  // the exit status
};

Subcommand AddInfo(CLI::App& parent);
Subcommand AddConvert(CLI::App& parent);
Subcommand AddExport(CLI::App& parent);
Subcommand AddMerge(CLI::App& parent);
Subcommand AddSimulate(CLI::App& parent);
Subcommand AddSimulateImu(CLI::App& parent);
Subcommand AddBuildMap(CLI::App& parent);
Subcommand AddMapInfo(CLI::App& parent);
Subcommand AddLocalize(CLI::App& parent);
Subcommand AddEvaluate(CLI::App& parent);
Subcommand AddRefine(CLI::App& parent);
Subcommand AddOdometry(CLI::App& parent);
Subcommand AddSlam(CLI::App& parent);
Subcommand AddRelocalize(CLI::App& parent);
Subcommand AddCalibrate(CLI::App& parent);

// The flags every subcommand that reads a sequence shares; the trajectory
// that gives the scans their poses is `poses_flag` (refine: --poses).
void AddSequenceOptions(
    CLI::App* app, SequenceOptions& options, const std::string& poses_flag = "--gt",
    const std::string& poses_help = "Ground-truth trajectory (TUM, or BAG:/topic[:child] of a ROS 2 bag)");

// Before a run: every output of `command` (--out, --mcap, --ply) can be
// written, no two name the same path, and none is a file or
// folder the command reads (its other flags, `config_path`); DataError
// naming the flags otherwise. What a folder holds is checked as it is
// written (read_file.hpp, ProtectInputs).
void CheckRunPaths(const CLI::App& command, const std::string& config_path);
// `rig` written to `path` with its scans' paths absolute: a results folder's
// rig file reads from anywhere.
void WriteRigWithAbsolutePaths(const std::string& path, Rig rig);

// Throws DataError when a weight w > 0 needs RCS and no scan of the sequence
// has it: before any map is built or scan matched.
void CheckRcsWeights(const Sequence& sequence, const std::vector<double>& weights);
// A weight as configuration names show it (%g).
std::string FormatWeight(double w);
// Checks of number flags that refuse NaN and inf (CLI11's ranges let them
// through) and state the range briefly: "[0, 1]", "(0, inf)".
const CLI::Validator& FiniteNumber();
CLI::Validator InRange(double lo, double hi, bool open_below = false);
CLI::Validator Positive();
CLI::Validator NonNegative();
// Adds FiniteNumber to every floating-point flag of `app` and its subcommands.
void CheckEveryNumberIsFinite(CLI::App& app);

// The map-building flags of build-map and localize: MapOptionTable's.
struct MapBuildSettings {
  MapOptions map;
};
void AddMapBuildOptions(CLI::App* app, MapBuildSettings& settings);

// The geometry of the map of `sequence`, with a progress bar; prints the
// cloud and Gaussian counts when `verbose`.
MapGeometry BuildGeometry(const Sequence& sequence, const MapBuildSettings& settings, bool verbose);
// Its RCS models for one incidence model and degree; prints the fit's
// summary when `verbose`.
GaussianMap FitRcsModelsOf(const MapGeometry& geometry, const MapBuildSettings& settings, IncidenceModel incidence,
                           int degree, bool verbose);

// The results folder `run` as an MCAP file (run_mcap.hpp) at `mcap`, with
// the scans registered by the run's poses (matched by stamp) and the
// reference aligned to the run at its first pose.
void WriteRunForViewer(const std::string& run, const std::vector<RadarScan>& scans,
                       const std::optional<Trajectory>& reference, const std::string& mcap);

// reference.tum of a localisation experiment into `out`: the reference pose
// of each matched scan (times in scan order; repeated times once).
void WriteReferenceTrajectory(const std::string& out, const std::vector<double>& times,
                              const std::vector<SE3d>& references);

}  // namespace radargauss::cli
