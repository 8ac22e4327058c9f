// SPDX-License-Identifier: BSD-3-Clause
// Odometry's outputs (docs/cli.md, "odometry").
#include <algorithm>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <optional>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/conventions.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/odometry/mounting.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/core/stats.hpp"

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
    s.p90_ms = PercentileOfSorted(times, 0.9);
  }
  s.active_gaussians = odometry.map().gaussians();
  s.global_gaussians = odometry.map().global_gaussians();
  s.map_bytes = odometry.map().MemoryBytes();
  return s;
}

namespace {

void WritePerScan(std::ostream& out, const std::vector<OdometryStep>& steps) {
  out << "scan,stamp,points,static_points,velocity_measured,vx,vy,vz,vx_std,vy_std,vz_std,standstill,gyro,matched,"
         "iterations,final_cost,converged,reason,keyframe,active_gaussians,active_map_bytes,time_ms,"
         "map_update_ms\n";
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
        << ',' << s.active_map_bytes << ',' << s.time_ms << ',' << s.map_update_ms << '\n';
  }
}

}  // namespace

namespace {

std::vector<double> Values(const Eigen::VectorXd& v, double scale = 1.0) {
  std::vector<double> out;
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(v(i) * scale);
  return out;
}

// The window's last estimate of what does not change along the drive, with its standard deviations.
nlohmann::json Calibration(const InertialMotion& inertial) {
  const auto& states = inertial.states();
  if (states.empty() || !states.back()) return nullptr;  // the window never started
  const InertialWindow& window = inertial.window();
  const InertialState& last = *states.back();
  const WindowUncertainty u = window.Uncertainty();
  constexpr double kDeg = 180.0 / M_PI;
  nlohmann::json c = {{"tilt_roll_pitch_deg", Values(window.tilt(), kDeg)},
                      {"tilt_std_deg", Values(u.tilt, kDeg)},
                      {"gyro_bias", Values(last.bias.gyro)},
                      {"gyro_bias_std", Values(u.gyro_bias)},
                      {"accel_bias", Values(last.bias.accel)},
                      {"accel_bias_std", Values(u.accel_bias)}};
  const InertialWindowOptions& o = inertial.options().window;
  if (o.estimate_clock_offset) {
    c["clock_offset_s"] = window.clock_offset();
    c["clock_offset_std_s"] = u.clock_offset;
  }
  if (o.estimate_elevation_bias) {
    c["elevation_bias_deg"] = window.elevation_bias() * kDeg;
    c["elevation_bias_std_deg"] = u.elevation_bias * kDeg;
  }
  // Calibration only where the motion shows it: per parameter, the share
  // of the solves whose data observed every direction, and the last solve's.
  const auto observed = [&](const char* name, const auto& directions, int size) {
    std::size_t all = 0;
    for (const WindowSolveSummary& solve : inertial.solves()) all += directions(solve.calibration) == size;
    const int last = inertial.solves().empty() ? 0 : directions(inertial.solves().back().calibration);
    c["observed"][name] = {{"share", inertial.solves().empty() ? 0.0 : double(all) / inertial.solves().size()},
                           {"directions_now", last},
                           {"status", last == size ? "observed"
                                      : last > 0   ? "partly observed"
                                                   : "not observed yet"}};
  };
  if (o.estimate_clock_offset)
    observed(
        "clock_offset", [](const CalibrationObservation& c) { return c.clock_offset; }, 1);
  if (o.estimate_elevation_bias) {
    observed(
        "elevation_bias", [](const CalibrationObservation& c) { return c.elevation_bias; }, 1);
  }
  if (o.estimate_extrinsic_rotation) {
    observed(
        "extrinsic_rotation", [](const CalibrationObservation& c) { return c.extrinsic_rotation; }, 3);
  }
  if (o.estimate_extrinsic_translation) {
    observed(
        "extrinsic_translation", [](const CalibrationObservation& c) { return c.extrinsic_translation; }, 3);
  }
  if (o.estimate_extrinsic_rotation || o.estimate_extrinsic_translation) {
    const SE3d radar_from_imu = window.radar_from_imu();
    c["radar_from_imu_rotation_vector_deg"] = Values(radar_from_imu.rotation().Log(), kDeg);
    c["radar_from_imu_translation"] = Values(radar_from_imu.translation());
    c["imu_from_radar_rotation_std_deg"] = Values(u.extrinsic_rotation, kDeg);
    c["imu_from_radar_translation_std"] = Values(u.extrinsic_translation);
  }
  return c;
}

// The window's solves: iterations per solve (mean, max) and integrations again.
nlohmann::json WindowSolves(const InertialMotion& inertial) {
  const std::vector<WindowSolveSummary>& solves = inertial.solves();
  if (solves.empty()) return nullptr;
  double iterations = 0.0;
  int most = 0;
  std::size_t reintegrated = 0, clock_offset_held = 0;
  for (const WindowSolveSummary& solve : solves) {
    iterations += solve.iterations;
    most = std::max(most, solve.iterations);
    reintegrated += solve.reintegrated;
    clock_offset_held += solve.clock_offset_held;
  }
  return {{"solves", solves.size()},
          {"iterations_mean", iterations / double(solves.size())},
          {"iterations_max", most},
          {"reintegrated", reintegrated},
          {"clock_offset_held", clock_offset_held}};
}

// inertial.csv: the window's newest state per scan (empty fields before it
// started), then each estimated calibration parameter as that scan's solve
// left it, its std as the window stated it before the solve and how many of
// its directions the data observed (docs/design/odometry.md, "Radar-inertial
// odometry").
void WriteInertialStates(const std::string& path, const RadarOdometry& odometry, const InertialMotion& inertial) {
  const InertialWindowOptions& o = inertial.options().window;
  using Columns = std::vector<double>;
  // Per estimated parameter: its header, and its values from one solve.
  std::vector<std::pair<std::string, std::function<Columns(const CalibrationObservation&)>>> calibration;
  if (o.estimate_extrinsic_rotation) {
    calibration.push_back(
        {"rotation_x_deg,rotation_y_deg,rotation_z_deg,rotation_std_x_deg,rotation_std_y_deg,"
         "rotation_std_z_deg,rotation_observed",
         [](const CalibrationObservation& c) {
           const Eigen::Vector3d r = c.radar_from_imu.rotation().Log() * kDegreesPerRadian;
           const Eigen::Vector3d s = c.extrinsic_rotation_std * kDegreesPerRadian;
           return Columns{r.x(), r.y(), r.z(), s.x(), s.y(), s.z(), double(c.extrinsic_rotation)};
         }});
  }
  if (o.estimate_extrinsic_translation) {
    calibration.push_back(
        {"translation_x,translation_y,translation_z,translation_std_x,translation_std_y,"
         "translation_std_z,translation_observed",
         [](const CalibrationObservation& c) {
           const Eigen::Vector3d t = c.radar_from_imu.translation();
           const Eigen::Vector3d s = c.extrinsic_translation_std;
           return Columns{t.x(), t.y(), t.z(), s.x(), s.y(), s.z(), double(c.extrinsic_translation)};
         }});
  }
  if (o.estimate_clock_offset) {
    calibration.push_back(
        {"clock_offset_s,clock_offset_std_s,clock_offset_observed", [](const CalibrationObservation& c) {
           return Columns{c.clock_offset_value, c.clock_offset_std, double(c.clock_offset)};
         }});
  }
  if (o.estimate_elevation_bias) {
    calibration.push_back(
        {"elevation_bias_deg,elevation_bias_std_deg,elevation_bias_observed", [](const CalibrationObservation& c) {
           return Columns{c.elevation_bias_value * kDegreesPerRadian, c.elevation_bias_std * kDegreesPerRadian,
                          double(c.elevation_bias)};
         }});
  }
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "stamp,vx,vy,vz,bgx,bgy,bgz,bax,bay,baz";
    for (const auto& [header, values] : calibration) out << ',' << header;
    out << '\n' << std::setprecision(9);
    const std::vector<OdometryStep>& steps = odometry.steps();
    std::size_t solve = 0;  // a scan with a state is a scan the window solved
    for (std::size_t k = 0; k < steps.size() && k < inertial.states().size(); ++k) {
      out << std::fixed << std::setprecision(9) << steps[k].stamp << std::defaultfloat << std::setprecision(9);
      const std::optional<InertialState>& s = inertial.states()[k];
      for (int i = 0; i < 9; ++i) {
        out << ',';
        if (!s) continue;
        out << (i < 3 ? s->velocity(i) : i < 6 ? s->bias.gyro(i - 3) : s->bias.accel(i - 6));
      }
      const WindowSolveSummary* solved = s && solve < inertial.solves().size() ? &inertial.solves()[solve++] : nullptr;
      for (const auto& [header, values] : calibration) {
        const Columns columns = values(solved ? solved->calibration : CalibrationObservation{});
        for (const double v : columns) {
          out << ',';
          if (solved) out << v;
        }
      }
      out << '\n';
    }
  });
}

}  // namespace

void WriteOdometry(const std::string& dir, const RadarOdometry& odometry) {
  const InertialMotion* inertial = InertialMotionOf(odometry);
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
  if (inertial != nullptr) {
    summary["calibration"] = Calibration(*inertial);
    summary["window"] = WindowSolves(*inertial);
    summary["imu_dropped"] = {{"beyond_range", inertial->screening().beyond_range},
                              {"spikes", inertial->screening().spikes}};
    const ImuHealth& health = inertial->health();
    summary["imu_health"] = {
        {"checked", inertial->options().health_check},
        {"dropped", false},
        {"verified", health.verified()},
        {"confirmed_at_s", health.confirmed_at() ? nlohmann::json(*health.confirmed_at()) : nlohmann::json(nullptr)}};
    if (const std::optional<ImuFault>& fault = inertial->imu_fault()) {
      summary["imu_health"]["dropped"] = true;
      summary["imu_health"]["cause"] = fault->cause;
      summary["imu_health"]["at_s"] = fault->stamp;
    }
    WriteInertialStates((out / "inertial.csv").string(), odometry, *inertial);
  }
  WriteFileAtomically((out / "summary.json").string(),
                      [&](std::ostream& stream) { stream << summary.dump(2) << "\n"; });
  if (!odometry.options().map.keep_evicted) return;  // the map is only the active one: no map file
  const GaussianMap map = odometry.map().GlobalMap();
  WriteMap((out / "map.rgm").string(), map);
  ExportPly((out / "map.ply").string(), map);
}

}  // namespace radargauss
