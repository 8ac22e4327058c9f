// SPDX-License-Identifier: BSD-3-Clause
// radargauss calibrate: the offline calibration of a rig's extrinsics and
// clocks against its reference radar (docs/design/rig.md, "Calibration of a
// rig"); with --compare, the errors against a rig file that holds the truth.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "option_flags.hpp"
#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/imu.hpp"
#include "radargauss/io/rig.hpp"
#include "radargauss/io/sequence.hpp"
#include "radargauss/odometry/rig_calibration.hpp"

namespace radargauss::cli {

namespace {

namespace fs = std::filesystem;

struct CalibrateSettings {
  std::string rig;
  std::string compare;
  std::string out;
  RigCalibrationOptions calibration;
  std::string imu;            // --imu: an IMU on the body
  std::string imu_extrinsic;  // T_body_imu
  RadarInertialOptions inertial;
};

// The IMU on the body (docs/design/rig.md, "Calibration of a rig"), when given.
std::optional<RigImu> ImuOf(const CalibrateSettings& s) {
  if (s.imu.empty()) {
    if (!s.imu_extrinsic.empty()) throw DataError("--imu-extrinsic needs --imu");
    return std::nullopt;
  }
  CheckOptions(RadarInertialOptionTable(), s.inertial);
  if (s.inertial.fusion != "window") throw DataError("--imu-fusion: the calibration takes the IMU's window");
  RigImu imu;
  imu.samples = ReadImuFile(s.imu);
  if (imu.samples.empty()) throw DataError(s.imu + ": no IMU sample");
  if (!s.imu_extrinsic.empty()) imu.body_from_imu = ReadStatedExtrinsicFile(s.imu_extrinsic).pose;
  imu.inertial = s.inertial;
  return imu;
}

constexpr double kDeg = 180.0 / M_PI;

// A standard deviation as JSON: null where the drive leaves it unobserved.
nlohmann::json Std(double value, double scale) {
  return std::isfinite(value) ? nlohmann::json(value * scale) : nlohmann::json(nullptr);
}

nlohmann::json Stds(const Eigen::Vector3d& values, double scale) {
  return {Std(values.x(), scale), Std(values.y(), scale), Std(values.z(), scale)};
}

// How far `a` is from `b`: rotation (deg), translation (m), clock (ms).
struct Difference {
  double rotation_deg = 0.0, translation = 0.0, clock_ms = 0.0;
};

Difference Between(const RigRadar& a, const RigRadar& b) {
  return {(b.body_from_radar.rotation().Inverse() * a.body_from_radar.rotation()).Log().norm() * kDeg,
          (a.body_from_radar.translation() - b.body_from_radar.translation()).norm(),
          1e3 * (a.clock_offset - b.clock_offset)};
}

// One radar's row of the printed table and its entry of calibration.json:
// the calibration, how far it moved from `given`, and its error against `truth`.
nlohmann::json ReportRadar(const RadarCalibration& c, const RigRadar& calibrated, const RigRadar& given,
                           const RigRadar* truth) {
  const Difference moved = Between(calibrated, given);
  const Eigen::Vector3d& t = c.body_from_radar.translation();
  const Eigen::Quaterniond& q = c.body_from_radar.rotation().quaternion();
  nlohmann::json entry = {
      {"name", c.name},
      {"translation", {t.x(), t.y(), t.z()}},
      {"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}},
      {"clock_offset", c.clock_offset},
      {"rotation_std_deg", Stds(c.rotation_std, kDeg)},
      {"translation_std_m", Stds(c.translation_std, 1.0)},
      {"clock_offset_std_ms", Std(c.clock_offset_std, 1e3)},
      {"scans", c.scans},
      {"doppler_points", c.doppler_points},
      {"map_points", c.map_points},
      {"moved",
       {{"rotation_deg", moved.rotation_deg}, {"translation_m", moved.translation}, {"clock_ms", moved.clock_ms}}}};
  const auto text = [](const Eigen::Vector3d& v, double scale) {
    char out[96];
    std::snprintf(out, sizeof(out), "%.3g %.3g %.3g", v.x() * scale, v.y() * scale, v.z() * scale);
    return std::string(out);
  };
  std::printf("| %s | %zu | %zu / %zu | %.3f | %.4f | %.2f | %s | %s | %.3g |", c.name.c_str(), c.scans,
              c.doppler_points, c.map_points, moved.rotation_deg, moved.translation, moved.clock_ms,
              text(c.rotation_std, kDeg).c_str(), text(c.translation_std, 1.0).c_str(), 1e3 * c.clock_offset_std);
  if (truth) {
    const Difference error = Between(calibrated, *truth);
    entry["error"] = {
        {"rotation_deg", error.rotation_deg}, {"translation_m", error.translation}, {"clock_ms", error.clock_ms}};
    std::printf(" %.3f | %.4f | %.2f |", error.rotation_deg, error.translation, error.clock_ms);
  }
  std::printf("\n");
  return entry;
}

int RunCalibrate(const CalibrateSettings& s) {
  ValidateOptions(s.calibration);
  const Rig rig = ReadRig(s.rig);
  std::optional<Rig> truth;
  if (!s.compare.empty()) {
    truth = ReadRig(s.compare);
    if (truth->radars.size() != rig.radars.size()) {
      throw DataError("--compare: " + std::to_string(truth->radars.size()) + " radars, the rig has " +
                      std::to_string(rig.radars.size()));
    }
  }
  if (rig.radars.size() < 2) throw DataError("--rig: calibration needs a reference radar and another");
  const std::optional<RigImu> imu = ImuOf(s);  // before the folder: a bad IMU leaves nothing behind
  StagedFolder folder(s.out);
  const RigCalibration result = CalibrateRig(rig, LoadRigScans(rig), s.calibration, imu);
  if (imu && !result.gyro) {
    std::fprintf(stderr,
                 "radargauss: warning: the IMU's window never ran (or dropped the IMU): the reference's "
                 "rates come from its poses\n");
  }
  WriteRigWithAbsolutePaths((fs::path(folder.path()) / "rig.yaml").string(), result.rig);
  nlohmann::json report = nlohmann::json::array();
  std::printf(
      "| radar | scans | Doppler / map points | moved deg | moved m | clock moved ms | rotation std deg | "
      "translation std m | clock std ms |%s\n",
      truth ? " error deg | error m | clock error ms |" : "");
  std::printf("|---|---|---|---|---|---|---|---|---|%s\n", truth ? "---|---|---|" : "");
  for (std::size_t r = 1; r < result.radars.size(); ++r) {
    report.push_back(
        ReportRadar(result.radars[r], result.rig.radars[r], rig.radars[r], truth ? &truth->radars[r] : nullptr));
  }
  {
    std::ofstream out(fs::path(folder.path()) / "calibration.json");
    out << nlohmann::json{{"reference", rig.radars.front().name}, {"gyro", result.gyro}, {"radars", report}}.dump(2)
        << "\n";
    if (!out) throw FileError(s.out + "/calibration.json", "cannot be written");
  }
  folder.Commit();
  std::printf("wrote %s (rig.yaml: the calibrated rig; calibration.json)\n", s.out.c_str());
  return 0;
}

}  // namespace

Subcommand AddCalibrate(CLI::App& parent) {
  auto s = std::make_shared<CalibrateSettings>();
  CLI::App* app = parent.add_subcommand("calibrate",
                                        "Calibrate a rig's extrinsics and clocks against its first radar over a drive");
  app->add_option("--rig", s->rig, "Rig file (docs/design/rig.md): the mountings and clocks to start from")->required();
  app->add_option("--out", s->out, "Output folder (rig.yaml: the calibrated rig; calibration.json)")->required();
  app->add_option("--compare", s->compare, "Rig file with the true mountings and clocks (a simulated rig's rig.yaml)");
  AddTableOptions(app, RigCalibrationOptionTable(), s->calibration);
  app->add_option("--imu", s->imu,
                  "IMU file on the body (lines 'stamp wx wy wz ax ay az'): the reference's odometry with its window "
                  "and its rates from the gyro");
  app->add_option("--imu-extrinsic", s->imu_extrinsic, "T_body_imu: a file 'x y z qx qy qz qw' (default: identity)");
  // The window at its defaults: its table's flags would meet the calibration's (estimate_clock_offset).
  app->add_option("--imu-clock-offset", s->inertial.window.clock_offset, "The IMU's stamps minus the body's clock (s)")
      ->capture_default_str();
  return {app, [s] { return RunCalibrate(*s); }};
}

}  // namespace radargauss::cli
