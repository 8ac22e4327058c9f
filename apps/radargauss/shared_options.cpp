// SPDX-License-Identifier: BSD-3-Clause
// The flags shared by several subcommands: the sequence, the map pipeline.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "commands.hpp"
#include "option_flags.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/progress.hpp"

namespace radargauss::cli {

void AddSequenceOptions(CLI::App* app, SequenceOptions& options, const std::string& poses_flag,
                        const std::string& poses_help) {
  app->add_option("--sequence", options.sequence_dir,
                  "Sequence folder: Snail-Radar layout (ars548/points/*.pcd), *.pcd or *.bin");
  app->add_option(poses_flag, options.ground_truth, poses_help);
  app->add_option("--extrinsic", options.extrinsic,
                  "T_gt_radar: auto, identity, snail-20231213, or a file 'x y z qx qy qz qw'")
      ->capture_default_str();
  app->add_option("--bag", options.bag,
                  "Bag of sensor_msgs/PointCloud2 scans: ROS1 .bag, ROS 2 .db3 or .mcap, or a rosbag2 folder");
  app->add_option("--topic", options.topic, "Topic of the scans in --bag");
  app->add_option("--bin-layout", options.bin_layout,
                  "Field order of .bin records (vod = 'x y z rcs v_r v_r_comp time')")
      ->capture_default_str();
  app->add_option("--rcs-field", options.fields.rcs_field,
                  "Field holding RCS (default: first of rcs RCS intensity power; 'none')");
  app->add_option("--doppler-field", options.fields.doppler_field,
                  "Field holding Doppler (default: first of doppler velocity v_r "
                  "radial_velocity vel; 'none')");
  app->add_option("--doppler-sign", options.fields.doppler_sign,
                  "Multiplies the file's Doppler to get 'positive receding' (+1 or -1)")
      ->check(CLI::IsMember({1.0, -1.0}))
      ->capture_default_str();
  app->add_option("--elevation-bias", options.elevation_bias_deg,
                  "The radar's elevation bias (deg), removed from every point as it is read")
      ->check(CLI::Range(-44.9, 44.9))
      ->capture_default_str();
}

void CheckRcsWeights(const Sequence& sequence, const std::vector<double>& weights) {
  const bool any_rcs =
      std::any_of(sequence.scans.begin(), sequence.scans.end(), [](const RadarScan& scan) { return scan.has_rcs; });
  const auto rcs_weight = std::find_if(weights.begin(), weights.end(), [](double w) { return w > 0.0; });
  if (!any_rcs && rcs_weight != weights.end()) {
    throw DataError("--w-rcs " + FormatWeight(*rcs_weight) +
                    " needs RCS, and the sequence has no RCS field (--rcs-field names it; --w-rcs 0 matches "
                    "geometry alone)");
  }
}

namespace {

// The message for a flag value stod cannot read; YAML spells NaN and inf
// as .nan and .inf.
std::string NotANumber(const std::string& text) {
  const bool yaml_special = text.find(".nan") != std::string::npos || text.find(".inf") != std::string::npos ||
                            text.find(".NaN") != std::string::npos || text.find(".Inf") != std::string::npos;
  return text + (yaml_special ? " is not a finite number" : " is not a number");
}

}  // namespace

const CLI::Validator& FiniteNumber() {
  static const CLI::Validator finite(
      [](std::string& text) {
        try {
          return std::isfinite(std::stod(text)) ? std::string() : text + " is not a finite number";
        } catch (const std::exception&) {
          return NotANumber(text);
        }
      },
      "FINITE");
  return finite;
}

CLI::Validator InRange(double lo, double hi, bool open_below) {
  const std::string range = (open_below ? "(" : "[") + FormatWeight(lo) + ", " +
                            (std::isinf(hi) ? std::string("inf)") : FormatWeight(hi) + "]");
  return CLI::Validator(
      [=](std::string& text) {
        double value = 0.0;
        try {
          value = std::stod(text);
        } catch (const std::exception&) {
          return NotANumber(text);
        }
        if (!std::isfinite(value)) return text + " is not a finite number";
        const bool below = open_below ? value <= lo : value < lo;
        return below || value > hi ? text + " is not in " + range : std::string();
      },
      range);
}

CLI::Validator Positive() { return InRange(0.0, INFINITY, true); }
CLI::Validator NonNegative() { return InRange(0.0, INFINITY); }

void CheckEveryNumberIsFinite(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    if (type.rfind("FLOAT", 0) == 0) option->check(CLI::Validator(FiniteNumber()).description(""));
  }
  for (CLI::App* sub : app.get_subcommands({})) CheckEveryNumberIsFinite(*sub);
}

void AddMapBuildOptions(CLI::App* app, MapBuildSettings& s) { AddTableOptions(app, MapOptionTable(), s.map); }

MapGeometry BuildGeometry(const Sequence& sequence, const MapBuildSettings& settings, bool verbose) {
  ProgressBar bar;
  MapGeometry geometry;
  try {
    geometry =
        BuildMapGeometry(sequence.scans, sequence.poses, settings.map,
                         [&](const char* step, std::size_t done, std::size_t total) { bar.Update(step, done, total); });
  } catch (const DataError& e) {  // no static point: say which flags decide what is static
    if (std::string(e.what()).rfind("no static points", 0) == 0 && settings.map.cloud.doppler_filter) {
      throw DataError(std::string(e.what()) +
                      " (static: Doppler inliers within --cloud-ego-min-range to "
                      "--cloud-ego-max-range; --doppler-filter false keeps every point)");
    }
    throw;
  }
  bar.Finish();
  if (verbose) {
    const MapCloudStats& stats = geometry.cloud_stats;
    std::printf("map cloud: %zu scans (%zu without ego velocity), %zu of %zu points static\n", stats.scans,
                stats.scans_without_ego_velocity, stats.points_static, stats.points_in);
    std::printf("gaussians: %zu (%s builder)\n", geometry.map.gaussians.size(),
                ToString(settings.map.gaussians.builder).c_str());
  }
  return geometry;
}

GaussianMap FitRcsModelsOf(const MapGeometry& geometry, const MapBuildSettings& settings, IncidenceModel incidence,
                           int degree, bool verbose) {
  RcsFitOptions rcs = settings.map.rcs;
  rcs.incidence = incidence;
  rcs.max_degree = degree;
  RcsFitStats stats;
  GaussianMap map = FitRcs(geometry, rcs, &stats);
  if (verbose) {
    std::printf(
        "rcs models (%s incidence, degree <= %d, %s): %zu with a model (%zu at a lowered "
        "degree), %zu without; mean fit RMSE %.4f\n",
        ToString(incidence).c_str(), degree, rcs.adaptive ? "adaptive" : "fixed", stats.with_model,
        stats.lowered_degree, stats.no_model, stats.mean_fit_rmse);
    if (stats.member_spread >= 0.0) {
      std::printf("rcs across frames (members' std, median over Gaussians of >= %zu): %.2f dB; by range",
                  RcsFitStats::kSpreadMinMembers, stats.member_spread);
      for (std::size_t b = 0; b < RcsFitStats::kRangeBins.size(); ++b) {
        std::printf(" %g+ m %.2f", RcsFitStats::kRangeBins[b], stats.member_spread_by_range[b]);
      }
      std::printf("; by |azimuth|");
      for (std::size_t b = 0; b < RcsFitStats::kAzimuthBins.size(); ++b) {
        std::printf(" %g+ deg %.2f", RcsFitStats::kAzimuthBins[b], stats.member_spread_by_azimuth[b]);
      }
      std::printf("\n");
    }
  }
  return map;
}

}  // namespace radargauss::cli
