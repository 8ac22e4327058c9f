// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/experiment/experiment.hpp"

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/stats.hpp"
#include "radargauss/core/trajectory.hpp"

namespace radargauss {

std::vector<SE3d> InitialErrors(std::size_t scans, double max_translation, double max_rotation_deg,
                                std::uint32_t seed) {
  if (scans > kMaxInitialErrors) {
    throw std::invalid_argument("InitialErrors: " + std::to_string(scans) + " scans is past " +
                                std::to_string(kMaxInitialErrors));
  }
  if (!(max_translation >= 0.0) || !std::isfinite(max_translation) || !(max_rotation_deg >= 0.0) ||
      !std::isfinite(max_rotation_deg)) {
    throw std::invalid_argument("InitialErrors: the largest translation and rotation must be finite and >= 0");
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal;
  const auto direction = [&] {
    Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
    return Eigen::Vector3d(v.normalized());
  };
  std::vector<SE3d> errors;
  for (std::size_t k = 0; k < scans; ++k) {
    const double translation = max_translation * unit(rng);
    const double angle = max_rotation_deg * M_PI / 180.0 * unit(rng);
    const Eigen::Vector3d t = translation * direction();
    errors.emplace_back(SO3d::Exp(angle * direction()), t);
  }
  return errors;
}

void PoseErrors(const SE3d& estimate, const SE3d& reference, double& translation, double& rotation_deg) {
  translation = (estimate.translation() - reference.translation()).norm();
  rotation_deg = (reference.rotation().Inverse() * estimate.rotation()).Log().norm() * 180.0 / M_PI;
}

void ConfigurationRun::Summarise() {
  std::vector<double> t, r;
  double iterations = 0.0, time = 0.0, converged = 0.0;
  for (const ScanOutcome& o : outcomes) {
    t.push_back(o.translation_error);
    r.push_back(o.rotation_error_deg);
    iterations += o.result.iterations;
    time += o.result.time_ms;
    converged += o.result.converged;
  }
  translation = Statistics(t);
  rotation = Statistics(r);
  const double n = std::max<double>(1.0, double(outcomes.size()));
  mean_iterations = iterations / n;
  mean_time_ms = time / n;
  converged_share = converged / n;
}

ConfigurationRun RunConfiguration(const std::string& name, double w_rcs, const ScanMatcher& matcher,
                                  const MatchingMap& map, const std::vector<RadarScan>& scans,
                                  const std::vector<SE3d>& references, const std::vector<SE3d>& errors,
                                  std::size_t first_scan) {
  ConfigurationRun run;
  run.name = name;
  run.w_rcs = w_rcs;
  run.outcomes.resize(scans.size());
  tbb::parallel_for(std::size_t(0), scans.size(), [&](std::size_t k) {
    ScanOutcome& o = run.outcomes[k];
    o.scan = first_scan + k;
    o.time = scans[k].timestamp;
    const SE3d initial = references[k] * errors[k];
    PoseErrors(initial, references[k], o.initial_translation_error, o.initial_rotation_error_deg);
    o.result = matcher.Match(scans[k], map, initial);
    PoseErrors(o.result.pose, references[k], o.translation_error, o.rotation_error_deg);
  });
  run.Summarise();
  return run;
}

namespace {

void WritePerScanCsv(const std::string& path, const std::vector<ConfigurationRun>& runs) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "scan,time,configuration,w_rcs,initial_translation_m,initial_rotation_deg,translation_m,"
           "rotation_deg,iterations,cost,n_geo,n_rcs,converged,time_ms\n";
    out.precision(9);
    for (const ConfigurationRun& run : runs) {
      for (const ScanOutcome& o : run.outcomes) {
        out << o.scan << ',' << std::fixed << o.time << std::defaultfloat << ',' << run.name << ',' << run.w_rcs << ','
            << o.initial_translation_error << ',' << o.initial_rotation_error_deg << ',' << o.translation_error << ','
            << o.rotation_error_deg << ',' << o.result.iterations << ',' << o.result.final_cost << ',' << o.result.n_geo
            << ',' << o.result.n_rcs << ',' << (o.result.converged ? 1 : 0) << ',' << o.result.time_ms << '\n';
      }
    }
  });
}

// summary.json, and each configuration's estimated trajectory (TUM).
void WriteSummaryAndTrajectories(const std::filesystem::path& dir, const std::vector<ConfigurationRun>& runs) {
  nlohmann::json summary = nlohmann::json::array();
  for (const ConfigurationRun& run : runs) {
    const auto stats = [](const ErrorStatistics& s) {
      return nlohmann::json{{"mean", s.mean}, {"median", s.median}, {"rmse", s.rmse}, {"max", s.max}};
    };
    summary.push_back({{"configuration", run.name},
                       {"w_rcs", run.w_rcs},
                       {"scans", run.outcomes.size()},
                       {"translation_m", stats(run.translation)},
                       {"rotation_deg", stats(run.rotation)},
                       {"mean_iterations", run.mean_iterations},
                       {"mean_time_ms", run.mean_time_ms},
                       {"converged_share", run.converged_share}});
    Trajectory trajectory;
    for (const ScanOutcome& o : run.outcomes) {
      if (trajectory.empty() || o.time > trajectory.EndTime()) trajectory.Append(o.time, o.result.pose);
    }
    WriteTum((dir / "trajectories" / (run.name + ".tum")).string(), trajectory, TumPrecision::kRoundTrip);
  }
  WriteFileAtomically((dir / "summary.json").string(), [&](std::ostream& out) { out << summary.dump(2) << "\n"; });
}

// The Markdown table, the best (lowest) value of each error column in bold.
std::string MarkdownTable(const std::vector<ConfigurationRun>& runs) {
  const auto column = [&](auto get) {
    double best = INFINITY;
    for (const ConfigurationRun& run : runs) best = std::min(best, get(run));
    return best;
  };
  using Getter = double (*)(const ConfigurationRun&);
  const std::vector<std::pair<const char*, Getter>> columns = {
      {"t mean [m]", [](const ConfigurationRun& r) { return r.translation.mean; }},
      {"t median [m]", [](const ConfigurationRun& r) { return r.translation.median; }},
      {"t RMSE [m]", [](const ConfigurationRun& r) { return r.translation.rmse; }},
      {"t max [m]", [](const ConfigurationRun& r) { return r.translation.max; }},
      {"r mean [deg]", [](const ConfigurationRun& r) { return r.rotation.mean; }},
      {"r median [deg]", [](const ConfigurationRun& r) { return r.rotation.median; }},
      {"r RMSE [deg]", [](const ConfigurationRun& r) { return r.rotation.rmse; }},
      {"r max [deg]", [](const ConfigurationRun& r) { return r.rotation.max; }},
  };
  std::ostringstream table;
  table << "| configuration |";
  for (const auto& [title, get] : columns) table << ' ' << title << " |";
  table << " iterations | ms/scan | converged |\n|---|";
  for (std::size_t i = 0; i < columns.size(); ++i) table << "---|";
  table << "---|---|---|\n";
  char cell[64];
  for (const ConfigurationRun& run : runs) {
    table << "| " << run.name << " |";
    for (const auto& [title, get] : columns) {
      const double value = get(run);
      std::snprintf(cell, sizeof(cell), value == column(get) ? " **%.3f** |" : " %.3f |", value);
      table << cell;
    }
    std::snprintf(cell, sizeof(cell), " %.1f | %.2f | %.0f%% |\n", run.mean_iterations, run.mean_time_ms,
                  100.0 * run.converged_share);
    table << cell;
  }
  return table.str();
}

}  // namespace

std::string WriteExperimentResults(const std::string& dir, const std::vector<ConfigurationRun>& runs) {
  namespace fs = std::filesystem;
  std::error_code error;
  fs::create_directories(fs::path(dir) / "trajectories", error);
  if (error) throw FileError(dir, "cannot create results folder: " + error.message());
  WritePerScanCsv((fs::path(dir) / "per_scan.csv").string(), runs);
  WriteSummaryAndTrajectories(dir, runs);
  const std::string markdown = MarkdownTable(runs);
  WriteFileAtomically((fs::path(dir) / "table.md").string(), [&](std::ostream& out) { out << markdown; });
  return markdown;
}

}  // namespace radargauss
