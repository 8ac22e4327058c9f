// SPDX-License-Identifier: BSD-3-Clause
// The simulator's configuration file and outputs.
#include "radargauss/simulator/simulator.hpp"

#include "config_keys.hpp"
#include "radargauss/simulator/imu_from_reference.hpp"

#include <algorithm>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <type_traits>
#include <utility>
#include <variant>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/pcd.hpp"
#include "radargauss/io/yaml_file.hpp"

namespace radargauss {

// ---------------------------------------------------------------------------
// Configuration file.

namespace {

constexpr double kMaxSimulatedSpeed = 150.0;  // m/s: 540 km/h, beyond any road vehicle
constexpr double kMaxSimulatedLength = 1e6;   // m: a loop, a range, an offset
constexpr double kMaxDecibels = 200.0;        // dB of noise, spread or loss

// A length (m) from 0 to kMaxSimulatedLength; a speed (m/s) to kMaxSimulatedSpeed.
template <typename Row>
Row Length(Row row) {
  return std::move(row).In(0.0, kMaxSimulatedLength).Unit("m");
}
template <typename Row>
Row Speed(Row row) {
  return std::move(row).In(0.0, kMaxSimulatedSpeed).Unit("m/s");
}

}  // namespace

// Below each range, what has no meaning (negative noise, speed, time); above
// it, what no radar on a road vehicle sees and where a draw overflows to inf
// or NaN (a growth of 1e300, traffic at 1e300 m/s). The IMU: up to 2 kHz,
// noise and biases up to what no working MEMS part exceeds tenfold.
const OptionTable<SimulationConfig>& SimulationOptionTable() {
  using O = SimulationConfig;
  constexpr double kMaxSeed = 4294967295.0;
  static const OptionTable<O> table = {
      RADARGAUSS_OPTION(O, "seed", seed).In(0, kMaxSeed).Help("seed of the noise and of the world"),
      RADARGAUSS_OPTION(O, "world_seed", world_seed).In(0, kMaxSeed).Help("seed of the scene's objects (0: seed's)"),
      Length(RADARGAUSS_OPTION(O, "start_offset", start_offset)).Help("where along the loop the drive starts"),
      RADARGAUSS_OPTION(O, "scans", scans).AtLeast(1).Help("scans of the drive"),
      RADARGAUSS_OPTION(O, "rate_hz", rate_hz).In(1e-3, 1e4).Unit("Hz").Help("the radar's scan rate"),
      RADARGAUSS_OPTION(O, "start_time", start_time).In(0.0, 1e10).Unit("s").Help("the first scan's stamp"),
      Speed(RADARGAUSS_OPTION(O, "speed", speed)).Help("the vehicle's speed along the loop"),
      Length(RADARGAUSS_OPTION(O, "loop_length", loop_length)).Help("the rounded-rectangle loop's length"),
      Length(RADARGAUSS_OPTION(O, "loop_width", loop_width)).Help("its width"),
      Length(RADARGAUSS_OPTION(O, "corner_radius", corner_radius)).Help("its corners' radius"),
      Length(RADARGAUSS_OPTION(O, "sensor_height", sensor_height)).Help("the radar above the ground"),
      RADARGAUSS_OPTION(O, "attitude_wobble_deg", attitude_wobble_deg)
          .In(0.0, 45.0)
          .Unit("deg")
          .Help("amplitude of the roll and pitch oscillation"),
      RADARGAUSS_OPTION(O, "azimuth_fov_deg", azimuth_fov_deg).In(0.0, 90.0).Unit("deg").Help("+- the field of view"),
      RADARGAUSS_OPTION(O, "elevation_fov_deg", elevation_fov_deg).In(0.0, 90.0).Unit("deg").Help("+- in elevation"),
      Length(RADARGAUSS_OPTION(O, "min_range", min_range)).Help("the nearest detection"),
      Length(RADARGAUSS_OPTION(O, "max_range", max_range)).Help("the farthest"),
      RADARGAUSS_OPTION(O, "min_detections", min_detections).AtLeast(1).Help("detections per scan, at least"),
      RADARGAUSS_OPTION(O, "max_detections", max_detections)
          .AtLeast(1)
          .NotBelow("min_detections")
          .Help("and at most (drawn uniformly)"),
      RADARGAUSS_OPTION(O, "max_rays", max_rays).AtLeast(1).Help("rays cast per scan at most"),
      RADARGAUSS_OPTION(O, "detection_threshold_db", detection_threshold_db)
          .In(-kMaxDecibels, kMaxDecibels)
          .Unit("dBsm")
          .Help("the weakest return detected"),
      RADARGAUSS_OPTION(O, "range_noise", range_noise).In(0.0, 100.0).Unit("m").Help("range noise (std)"),
      RADARGAUSS_OPTION(O, "azimuth_noise_deg", azimuth_noise_deg).In(0.0, 45.0).Unit("deg").Help("azimuth noise"),
      RADARGAUSS_OPTION(O, "elevation_noise_deg", elevation_noise_deg)
          .In(0.0, 45.0)
          .Unit("deg")
          .Help("elevation noise"),
      RADARGAUSS_OPTION(O, "doppler_noise", doppler_noise).In(0.0, 100.0).Unit("m/s").Help("Doppler noise"),
      RADARGAUSS_OPTION(O, "rcs_noise_db", rcs_noise_db).In(0.0, kMaxDecibels).Unit("dB").Help("RCS noise"),
      RADARGAUSS_OPTION(O, "clutter_fraction", clutter_fraction).In(0.0, 1.0).Help("share of clutter detections"),
      RADARGAUSS_OPTION(O, "rcs_outlier_fraction", rcs_outlier_fraction)
          .In(0.0, 1.0)
          .Help("share of detections with RCS + U(-25, 25) dB"),
      RADARGAUSS_OPTION(O, "elevation_bias_deg", elevation_bias_deg)
          .In(-90.0, 90.0)
          .Unit("deg")
          .Help("added to every elevation (within the field of view)"),
      RADARGAUSS_OPTION(O, "elevation_noise_growth", elevation_noise_growth)
          .In(0.0, 100.0)
          .Help("elevation std x (1 + growth (azimuth / azimuth_fov)^2)"),
      RADARGAUSS_OPTION(O, "mounting_roll_deg", mounting_roll_deg).In(-45.0, 45.0).Unit("deg").Help("the radar's roll"),
      RADARGAUSS_OPTION(O, "mounting_pitch_deg", mounting_pitch_deg)
          .In(-45.0, 45.0)
          .Unit("deg")
          .Help("its pitch (positive: looking down)"),
      RADARGAUSS_OPTION(O, "mounting_yaw_deg", mounting_yaw_deg)
          .In(-180.0, 180.0)
          .Unit("deg")
          .Help("its yaw (a corner radar's is 45 to 135)"),
      RADARGAUSS_OPTION(O, "mounting_x", mounting_x).In(-10.0, 10.0).Unit("m").Help("its place: forward"),
      RADARGAUSS_OPTION(O, "mounting_y", mounting_y).In(-10.0, 10.0).Unit("m").Help("to the left"),
      RADARGAUSS_OPTION(O, "mounting_z", mounting_z).In(-10.0, 10.0).Unit("m").Help("up"),
      RADARGAUSS_OPTION(O, "clock_offset", clock_offset)
          .In(-0.5, 0.5)
          .Unit("s")
          .Help("the radar's stamps minus the true time"),
      RADARGAUSS_OPTION(O, "rcs_swerling", rcs_swerling).In(0, 3).Help("RCS fluctuation: 0 none, 1 or 3 Swerling"),
      RADARGAUSS_OPTION(O, "multipath_probability", multipath_probability)
          .In(0.0, 1.0)
          .Help("a ray meeting a wall or guardrail also returns a ghost"),
      RADARGAUSS_OPTION(O, "multipath_loss_db", multipath_loss_db)
          .In(0.0, kMaxDecibels)
          .Unit("dB")
          .Help("the ghost's RCS below its target's"),
      RADARGAUSS_OPTION(O, "imu_rate_hz", imu_rate_hz).In(0.0, 2000.0).Unit("Hz").Help("the IMU's rate (0: none)"),
      RADARGAUSS_OPTION(O, "imu_gyro_noise_density", imu_noise.gyro_noise_density)
          .In(0.0, 0.1)
          .Unit("rad/s/sqrt(Hz)")
          .Help("the gyro's white noise"),
      RADARGAUSS_OPTION(O, "imu_accel_noise_density", imu_noise.accel_noise_density)
          .In(0.0, 1.0)
          .Unit("m/s^2/sqrt(Hz)")
          .Help("the accelerometer's"),
      RADARGAUSS_OPTION(O, "imu_gyro_bias_std", imu_gyro_bias_std)
          .In(0.0, 1.0)
          .Unit("rad/s")
          .Help("the gyro's turn-on bias (std per axis)"),
      RADARGAUSS_OPTION(O, "imu_accel_bias_std", imu_accel_bias_std)
          .In(0.0, 10.0)
          .Unit("m/s^2")
          .Help("the accelerometer's"),
      RADARGAUSS_OPTION(O, "imu_gyro_bias_random_walk", imu_noise.gyro_bias_random_walk)
          .In(0.0, 0.1)
          .Unit("rad/s^2/sqrt(Hz)")
          .Help("the gyro bias's random walk"),
      RADARGAUSS_OPTION(O, "imu_accel_bias_random_walk", imu_noise.accel_bias_random_walk)
          .In(0.0, 1.0)
          .Unit("m/s^3/sqrt(Hz)")
          .Help("the accelerometer bias's"),
      RADARGAUSS_OPTION(O, "imu_roll_deg", imu_roll_deg).In(-180.0, 180.0).Unit("deg").Help("the IMU on the vehicle"),
      RADARGAUSS_OPTION(O, "imu_pitch_deg", imu_pitch_deg).In(-180.0, 180.0).Unit("deg").Help("its pitch"),
      RADARGAUSS_OPTION(O, "imu_yaw_deg", imu_yaw_deg).In(-180.0, 180.0).Unit("deg").Help("its yaw"),
      RADARGAUSS_OPTION(O, "imu_x", imu_x).In(-10.0, 10.0).Unit("m").Help("its place: forward of the vehicle's origin"),
      RADARGAUSS_OPTION(O, "imu_y", imu_y).In(-10.0, 10.0).Unit("m").Help("to the left"),
      RADARGAUSS_OPTION(O, "imu_z", imu_z).In(-10.0, 10.0).Unit("m").Help("up"),
      RADARGAUSS_OPTION(O, "imu_clock_offset", imu_clock_offset)
          .In(-0.5, 0.5)
          .Unit("s")
          .Help("the IMU's stamps minus the true time"),
      RADARGAUSS_OPTION(O, "scene", scene).Choices({"town", "motorway"}).Help("the world along the loop"),
      Speed(RADARGAUSS_OPTION(O, "traffic_min_speed", traffic_min_speed)).Help("the motorway's cars, at least"),
      Speed(RADARGAUSS_OPTION(O, "traffic_max_speed", traffic_max_speed))
          .NotBelow("traffic_min_speed")
          .Help("and at most"),
      RADARGAUSS_OPTION(O, "poles", poles).AtLeast(0).Help("poles of the town"),
      RADARGAUSS_OPTION(O, "parked_cars", parked_cars).AtLeast(0).Help("its parked cars"),
      RADARGAUSS_OPTION(O, "moving_cars", moving_cars).AtLeast(0).Help("its moving cars"),
      Speed(RADARGAUSS_OPTION(O, "moving_car_speed", moving_car_speed)).Help("their speed"),
      RADARGAUSS_OPTION(O, "object_rcs_spread_db", object_rcs_spread_db)
          .In(0.0, kMaxDecibels)
          .Unit("dB")
          .Help("spread of the objects' RCS offsets"),
  };
  return table;
}

void ValidateSimulationConfig(const SimulationConfig& c, const std::string& source) {
  const auto require = [&](bool ok, const std::string& what) {
    if (!ok) throw FileError(source, what);
  };
  for (const Option<SimulationConfig>& option : SimulationOptionTable()) {
    const OptionValue value = option.get(c);
    if (const double* number = std::get_if<double>(&value)) {
      require(std::isfinite(*number), option.name + " must be a finite number");
    }
  }
  try {
    CheckOptions(SimulationOptionTable(), c);
  } catch (const std::invalid_argument& e) {
    throw FileError(source, e.what());
  }
  // What no row states alone: open ends and rules between keys.
  require(c.corner_radius > 0.0 && c.loop_length > 2.0 * c.corner_radius && c.loop_width > 2.0 * c.corner_radius,
          "loop_length and loop_width must exceed 2 x corner_radius > 0");
  require(c.sensor_height > 0.0, "sensor_height must be > 0");
  require(c.azimuth_fov_deg > 0.0, "azimuth_fov_deg must be in (0, 90]");
  require(c.elevation_fov_deg > 0.0 && c.elevation_fov_deg < 90.0, "elevation_fov_deg must be in (0, 90)");
  require(c.max_range > c.min_range, "need 0 <= min_range < max_range");
  require(c.clutter_fraction < 1.0, "clutter_fraction must be in [0, 1)");
  require(std::abs(c.elevation_bias_deg) < c.elevation_fov_deg, "elevation_bias_deg must be within the field of view");
  require(c.rcs_swerling != 2, "rcs_swerling must be 0, 1 or 3");
  require(double(c.scans - 1) / c.rate_hz * c.imu_rate_hz < double(kMaxImuSamples),
          "imu_rate_hz over the drive gives more than " + std::to_string(kMaxImuSamples) + " IMU samples");
  for (const char* name : {"ground", "wall", "pole", "car", "guardrail"}) {
    const auto it = c.materials.find(name);
    require(it != c.materials.end(), std::string("material '") + name + "' missing");
    require(std::isfinite(it->second.diffuse) && std::isfinite(it->second.specular) &&
                std::isfinite(it->second.lobe_width_deg),
            std::string("material '") + name + "' needs finite numbers");
    require(it->second.diffuse <= 1e6 && it->second.specular <= 1e6 && it->second.lobe_width_deg <= 180.0,
            std::string("material '") + name + "' needs diffuse, specular <= 1e6 m^2 and lobe_width_deg <= 180");
    require(it->second.diffuse >= 0.0 && it->second.specular >= 0.0 && it->second.lobe_width_deg > 0.0 &&
                it->second.diffuse + it->second.specular > 0.0,
            std::string("material '") + name + "' needs diffuse, specular >= 0 (not both 0) and lobe_width_deg > 0");
  }
}

std::size_t ImuSampleCount(const SimulationConfig& config) {
  if (!(config.imu_rate_hz > 0.0)) return 0;
  return std::size_t(std::floor((config.scans - 1) / config.rate_hz * config.imu_rate_hz + 1e-9)) + 1;
}

namespace {

// A YAML scalar as the row's kind of value (yaml-cpp's reading of numbers).
OptionValue ReadValue(const OptionSpec& option, const YAML::Node& node) {
  switch (option.kind) {
    case OptionKind::kInteger:
      return std::int64_t(node.as<long long>());
    case OptionKind::kReal:
      return node.as<double>();
    case OptionKind::kFlag:
      return node.as<bool>();
    default:
      return node.as<std::string>();
  }
}

}  // namespace

void ApplySimulationKeys(const YAML::Node& root, const std::string& path, SimulationConfig& config,
                         const std::vector<std::string>& refused, const std::string& why) {
  if (!root.IsMap()) throw FileError(path, "expected a map of parameters");
  const OptionTable<SimulationConfig>& table = SimulationOptionTable();
  for (const auto& entry : root) {
    if (!entry.first.IsScalar()) {
      throw FileError(path, entry.first.Mark().line + 1, "a key must be a parameter name");
    }
    const std::string key = entry.first.Scalar();
    if (std::find(refused.begin(), refused.end(), key) != refused.end()) throw FileError(path, key + ": " + why);
    try {
      if (key == "materials") {
        if (!entry.second.IsMap()) throw FileError(path, "materials must be a map");
        for (const auto& material : entry.second) {
          const std::string name = material.first.IsScalar() ? material.first.Scalar() : "";
          if (!config.materials.count(name)) {
            throw FileError(path, "unknown material '" + name + "' (ground, wall, pole, car, guardrail)");
          }
          Material& m = config.materials[name];
          if (!material.second.IsMap()) throw FileError(path, "material '" + name + "' must be a map");
          for (const auto& property : material.second) {
            const std::string property_name = property.first.IsScalar() ? property.first.Scalar() : "";
            if (property_name == "diffuse")
              m.diffuse = property.second.as<double>();
            else if (property_name == "specular")
              m.specular = property.second.as<double>();
            else if (property_name == "lobe_width_deg")
              m.lobe_width_deg = property.second.as<double>();
            else
              throw FileError(path, "unknown material property '" + property_name + "'");
          }
        }
        continue;
      }
      const Option<SimulationConfig>* option = FindOption(table, key);
      if (option == nullptr) throw FileError(path, "unknown parameter '" + key + "'");
      const OptionValue value = ReadValue(*option, entry.second);
      // An integer is checked before it is set, where it could wrap around.
      const std::string refused = option->kind == OptionKind::kInteger ? option->Check(value) : std::string();
      if (!refused.empty()) throw FileError(path, key + " = " + FormatOptionValue(value) + " " + refused);
      option->set(config, value);
    } catch (const YAML::Exception& e) {
      throw FileError(path, e.mark.line + 1, "parameter '" + key + "' has the wrong type");
    }
  }
}

SimulationConfig LoadSimulationConfig(const std::string& path) {
  SimulationConfig config;
  const YAML::Node root = ReadYamlDocument(path, "simulation config");
  if (root.IsNull()) return config;
  ApplySimulationKeys(root, path, config, {}, "");
  ValidateSimulationConfig(config, path);
  return config;
}

std::string SimulationConfigToYaml(const SimulationConfig& config) {
  std::ostringstream out;
  out.precision(17);
  for (const Option<SimulationConfig>& option : SimulationOptionTable()) {
    out << option.name << ": ";
    std::visit(
        [&](const auto& value) {
          if constexpr (!std::is_same_v<std::decay_t<decltype(value)>, std::vector<double>>) out << value;
        },
        option.get(config));
    out << "\n";
  }
  out << "materials:\n";
  for (const auto& [name, m] : config.materials) {
    out << "  " << name << ": {diffuse: " << m.diffuse << ", specular: " << m.specular
        << ", lobe_width_deg: " << m.lobe_width_deg << "}\n";
  }
  return out.str();
}

Sequence AsSequence(const SimulatedSequence& simulated) {
  Sequence sequence;
  sequence.layout = "simulated";
  sequence.scans = simulated.scans;
  sequence.total_scans = simulated.scans.size();
  sequence.trajectory = simulated.ground_truth;
  for (const StampedPose& sample : simulated.ground_truth) sequence.poses.push_back(sample.pose);
  return sequence;
}

void WriteSimulatedSequence(const std::string& dir, const SimulatedSequence& sequence) {
  namespace fs = std::filesystem;
  const fs::path points = fs::path(dir) / "ars548" / "points";
  std::error_code error;
  fs::create_directories(points, error);
  if (error) throw FileError(points.string(), "cannot create directory: " + error.message());
  std::string times;
  for (std::size_t k = 0; k < sequence.scans.size(); ++k) {
    const std::string& stem = sequence.file_stems[k];
    WritePcdScan((points / (stem + ".pcd")).string(), sequence.scans[k], PcdFormat::kBinary);
    times += stem + "\n";
  }
  WriteFileAtomically((points / "times.txt").string(), [&](std::ostream& out) { out << times; });
  WriteTum((fs::path(dir) / "gt_radar_tum.txt").string(), sequence.ground_truth);
  if (!sequence.imu.empty()) WriteImuFiles(dir, {sequence.imu, sequence.imu_bias}, sequence.radar_from_imu);
  WriteFileAtomically((fs::path(dir) / "simulation.yaml").string(), [&](std::ostream& out) {
    out << "# radargauss simulate: the configuration that produced this sequence\n"
        << SimulationConfigToYaml(sequence.config);
  });
}

}  // namespace radargauss
