// SPDX-License-Identifier: BSD-3-Clause
// radargauss simulate-imu: an IMU made for a recorded drive from its
// reference trajectory (docs/design/simulator.md, "An IMU from a reference").
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.hpp"
#include "option_flags.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/simulator/imu_from_reference.hpp"

namespace radargauss::cli {

namespace {

struct SimulateImuSettings {
  std::string gt;
  std::string out;
  double knot_spacing = 0.5;
  double smoothing = 0.0;
  double extend = 1.0;
  bool force = false;
  SimulationConfig imu;  // its imu_* rows and the seed
};

// The rows of the simulator's table that describe its IMU, and its seed.
const OptionTable<SimulationConfig>& ImuRows() {
  static const OptionTable<SimulationConfig> rows = [] {
    OptionTable<SimulationConfig> kept;
    for (const Option<SimulationConfig>& row : SimulationOptionTable()) {
      if (row.name != "seed" && row.name.rfind("imu_", 0) != 0) continue;
      kept.push_back(row);
      kept.back().group = OptionGroup::kSensor;  // this command's own flags: in --help
    }
    return kept;
  }();
  return rows;
}

int RunSimulateImu(const SimulateImuSettings& s) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!s.force && fs::exists(fs::path(s.out) / "imu.txt", error)) {
    throw FileError(s.out, "already holds an imu.txt (use --force to overwrite)");
  }
  const Trajectory reference = ReadTum(s.gt);
  // A knot needs poses to place it: at most four knots per reference pose.
  if (!reference.empty() &&
      (reference.EndTime() - reference.StartTime()) / s.knot_spacing > 4.0 * double(reference.size())) {
    throw DataError("--knot-spacing " + std::to_string(s.knot_spacing) + " s gives more than four knots per pose of " +
                    s.gt);
  }
  const SmoothTrajectory motion(reference, s.knot_spacing, s.smoothing);
  SimulationConfig config = s.imu;
  config.start_time = motion.start() - s.extend;
  const std::size_t count =
      std::size_t(std::floor((motion.end() - motion.start() + 2.0 * s.extend) * config.imu_rate_hz)) + 1;
  // The reference is the radar's: its frame is the "vehicle" the IMU is mounted on.
  const SE3d radar_from_imu = ImuOnVehicle(config);
  const SimulatedImu imu =
      SimulateImuAlong([&](double t) { return motion(config.start_time + t) * radar_from_imu; }, count, config);
  fs::create_directories(s.out, error);
  if (error) throw FileError(s.out, "cannot create directory: " + error.message());
  WriteImuFiles(s.out, imu, radar_from_imu);
  std::printf("simulated %zu IMU samples at %g Hz (seed %u) along %s into %s\n", imu.samples.size(), config.imu_rate_hz,
              config.seed, s.gt.c_str(), s.out.c_str());
  std::printf("smooth motion: knots every %g s, fit rms %.3f m and %.3f deg over %zu reference poses\n", s.knot_spacing,
              motion.position_rms(), motion.rotation_rms() * 180.0 / M_PI, reference.size());
  std::printf("imu: %s/imu.txt, imu_extrinsic.txt (T_radar_imu), imu_biases.txt (the truth)\n", s.out.c_str());
  return 0;
}

}  // namespace

Subcommand AddSimulateImu(CLI::App& parent) {
  auto s = std::make_shared<SimulateImuSettings>();
  s->imu.imu_rate_hz = 200.0;
  CLI::App* app = parent.add_subcommand("simulate-imu", "Make an IMU for a recorded drive from its reference");
  app->add_option("--gt", s->gt, "Reference trajectory (TUM, the radar's poses; gravity along its -z)")->required();
  app->add_option("--out", s->out, "Output folder: imu.txt, imu_extrinsic.txt, imu_biases.txt")->required();
  app->add_option("--knot-spacing", s->knot_spacing, "Seconds between the smoothing spline's knots")
      ->check(Positive())
      ->capture_default_str();
  app->add_option("--smoothing", s->smoothing, "Weight of the spline's second differences")
      ->check(InRange(0.0, 1e6))
      ->capture_default_str();
  app->add_option("--extend", s->extend, "Seconds of IMU before and after the reference (at its end motion)")
      ->check(InRange(0.0, 60.0))
      ->capture_default_str();
  AddBoolFlag(app, "--force", s->force, "Overwrite the IMU files in --out");
  AddTableOptions(app, ImuRows(), s->imu);
  return {app, [s] {
            if (!(s->imu.imu_rate_hz > 0.0)) throw DataError("--imu-rate-hz must be above zero");
            return RunSimulateImu(*s);
          }};
}

}  // namespace radargauss::cli
