// SPDX-License-Identifier: BSD-3-Clause
// Odometry's outputs (docs/cli.md, "odometry").
#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <system_error>

#include <nlohmann/json.hpp>

#include "radargauss/atomic_file.hpp"
#include "radargauss/error.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/odometry/mounting.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/stats.hpp"

namespace radargauss {

OdometrySummary Summarise(const RadarOdometry& odometry) {
  OdometrySummary s;
  std::vector<double> times;
  const std::vector<OdometryStep>& steps = odometry.steps();
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const OdometryStep& step = steps[k];
    times.push_back(step.time_ms);
    s.keyframes += step.keyframe;
    s.matched += step.matched;
    s.velocity_predicted += !step.velocity_measured;
    s.standstill += step.standstill;
    s.pose_predicted += k > 0 && !step.matched && !step.standstill;
    if (k > 0) s.path_length += (step.pose.translation() - steps[k - 1].pose.translation()).norm();
  }
  s.scans = steps.size();
  std::sort(times.begin(), times.end());
  if (!times.empty()) {
    s.median_ms = MedianOfSorted(times);
    s.p90_ms = times[std::min(times.size() - 1, std::size_t(0.9 * double(times.size())))];
  }
  s.active_gaussians = odometry.map().gaussians();
  s.global_gaussians = odometry.map().global_gaussians();
  s.map_bytes = odometry.map().MemoryBytes();
  return s;
}

namespace {

void WritePerScan(std::ostream& out, const std::vector<OdometryStep>& steps) {
  out << "scan,stamp,points,static_points,velocity_measured,vx,vy,vz,vx_std,vy_std,vz_std,standstill,gyro,matched,"
         "iterations,final_cost,converged,reason,keyframe,active_gaussians,active_map_bytes,time_ms\n";
  out << std::setprecision(9);
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const OdometryStep& s = steps[k];
    const Eigen::Vector3d velocity_std = s.velocity_covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
    std::string reason = s.reason;
    std::replace(reason.begin(), reason.end(), '"', '\'');
    out << k << ',' << std::fixed << std::setprecision(9) << s.stamp << std::defaultfloat << std::setprecision(9) << ','
        << s.points << ',' << s.static_points << ',' << s.velocity_measured << ',' << s.velocity.x() << ','
        << s.velocity.y() << ',' << s.velocity.z() << ',' << velocity_std.x() << ',' << velocity_std.y() << ','
        << velocity_std.z() << ',' << s.standstill << ',' << s.gyro << ',' << s.matched << ',' << s.iterations << ','
        << s.final_cost << ',' << s.converged << ",\"" << reason << "\"," << s.keyframe << ',' << s.active_gaussians
        << ',' << s.active_map_bytes << ',' << s.time_ms << '\n';
  }
}

}  // namespace

void WriteOdometry(const std::string& dir, const RadarOdometry& odometry) {
  namespace fs = std::filesystem;
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) throw FileError(dir, "cannot create the output folder: " + error.message());
  const fs::path out(dir);
  WriteTum((out / "odometry.tum").string(), odometry.trajectory());
  WriteFileAtomically((out / "per_scan.csv").string(),
                      [&](std::ostream& stream) { WritePerScan(stream, odometry.steps()); });
  const OdometrySummary s = Summarise(odometry);
  nlohmann::json summary = {{"scans", s.scans},
                            {"keyframes", s.keyframes},
                            {"matched", s.matched},
                            {"velocity_predicted", s.velocity_predicted},
                            {"standstill", s.standstill},
                            {"pose_predicted", s.pose_predicted},
                            {"path_length_m", s.path_length},
                            {"median_time_ms", s.median_ms},
                            {"p90_time_ms", s.p90_ms},
                            {"active_gaussians", s.active_gaussians},
                            {"global_gaussians", s.global_gaussians},
                            {"active_map_bytes", s.map_bytes}};
  if (odometry.options().elevation_bias.estimate) {
    summary["elevation_bias_deg"] = odometry.elevation_bias_deg();
  }
  summary["mounting"] = nullptr;  // not observable: too few straight scans at speed
  if (const std::optional<Mounting> mounting = EstimateMounting(odometry.steps())) {
    const Trajectory levelled = Levelled(odometry.trajectory(), *mounting);
    const Eigen::Vector3d end = levelled[levelled.size() - 1].pose.translation();  // a mounting needs scans
    summary["mounting"] = {{"pitch_deg", mounting->pitch_deg},
                           {"yaw_deg", mounting->yaw_deg},
                           {"pitch_spread_deg", mounting->pitch_spread_deg},
                           {"yaw_spread_deg", mounting->yaw_spread_deg},
                           {"pitch_scans", mounting->pitch_scans},
                           {"yaw_scans", mounting->yaw_scans},
                           {"levelled_end_m", {end.x(), end.y(), end.z()}}};
    WriteTum((out / "levelled.tum").string(), levelled);
  }
  WriteFileAtomically((out / "summary.json").string(),
                      [&](std::ostream& stream) { stream << summary.dump(2) << "\n"; });
  const GaussianMap map = odometry.map().GlobalMap();
  WriteMap((out / "map.rgm").string(), map);
  ExportPly((out / "map.ply").string(), map);
}

}  // namespace radargauss
