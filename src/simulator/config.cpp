// SPDX-License-Identifier: BSD-3-Clause
// The simulator's configuration file and outputs.
#include "radargauss/simulator/simulator.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <sstream>
#include <tuple>
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

std::string Number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

using ConfigValue = std::variant<double*, int*, std::uint32_t*, std::string*>;

std::vector<std::pair<std::string, ConfigValue>> ConfigFields(SimulationConfig& c) {
  return {{"seed", &c.seed},
          {"world_seed", &c.world_seed},
          {"start_offset", &c.start_offset},
          {"scans", &c.scans},
          {"rate_hz", &c.rate_hz},
          {"start_time", &c.start_time},
          {"speed", &c.speed},
          {"loop_length", &c.loop_length},
          {"loop_width", &c.loop_width},
          {"corner_radius", &c.corner_radius},
          {"sensor_height", &c.sensor_height},
          {"attitude_wobble_deg", &c.attitude_wobble_deg},
          {"azimuth_fov_deg", &c.azimuth_fov_deg},
          {"elevation_fov_deg", &c.elevation_fov_deg},
          {"min_range", &c.min_range},
          {"max_range", &c.max_range},
          {"min_detections", &c.min_detections},
          {"max_detections", &c.max_detections},
          {"max_rays", &c.max_rays},
          {"detection_threshold_db", &c.detection_threshold_db},
          {"range_noise", &c.range_noise},
          {"azimuth_noise_deg", &c.azimuth_noise_deg},
          {"elevation_noise_deg", &c.elevation_noise_deg},
          {"doppler_noise", &c.doppler_noise},
          {"rcs_noise_db", &c.rcs_noise_db},
          {"clutter_fraction", &c.clutter_fraction},
          {"rcs_outlier_fraction", &c.rcs_outlier_fraction},
          {"elevation_bias_deg", &c.elevation_bias_deg},
          {"elevation_noise_growth", &c.elevation_noise_growth},
          {"mounting_roll_deg", &c.mounting_roll_deg},
          {"mounting_pitch_deg", &c.mounting_pitch_deg},
          {"mounting_yaw_deg", &c.mounting_yaw_deg},
          {"rcs_swerling", &c.rcs_swerling},
          {"multipath_probability", &c.multipath_probability},
          {"multipath_loss_db", &c.multipath_loss_db},
          {"imu_rate_hz", &c.imu_rate_hz},
          {"imu_gyro_noise_density", &c.imu_gyro_noise_density},
          {"imu_accel_noise_density", &c.imu_accel_noise_density},
          {"imu_gyro_bias_std", &c.imu_gyro_bias_std},
          {"imu_accel_bias_std", &c.imu_accel_bias_std},
          {"imu_gyro_bias_random_walk", &c.imu_gyro_bias_random_walk},
          {"imu_accel_bias_random_walk", &c.imu_accel_bias_random_walk},
          {"imu_roll_deg", &c.imu_roll_deg},
          {"imu_pitch_deg", &c.imu_pitch_deg},
          {"imu_yaw_deg", &c.imu_yaw_deg},
          {"imu_x", &c.imu_x},
          {"imu_y", &c.imu_y},
          {"imu_z", &c.imu_z},
          {"imu_clock_offset", &c.imu_clock_offset},
          {"scene", &c.scene},
          {"traffic_min_speed", &c.traffic_min_speed},
          {"traffic_max_speed", &c.traffic_max_speed},
          {"poles", &c.poles},
          {"parked_cars", &c.parked_cars},
          {"moving_cars", &c.moving_cars},
          {"moving_car_speed", &c.moving_car_speed},
          {"object_rcs_spread_db", &c.object_rcs_spread_db}};
}

// The ranges of the magnitudes, both ends: below, what has no meaning
// (negative noise, speed, time); above, what no radar on a road vehicle sees
// and where a draw overflows to inf or NaN (a growth of 1e300, traffic at 1e300 m/s).
void ValidateMagnitudes(const SimulationConfig& c, const std::string& source) {
  const auto bounded = [&](double value, double low, double high, const std::string& key) {
    if (!(value >= low && value <= high)) {
      throw FileError(source, key + " must be in [" + Number(low) + ", " + Number(high) + "], not " + Number(value));
    }
  };
  bounded(c.rate_hz, 1e-3, 1e4, "rate_hz");
  bounded(c.start_time, 0.0, 1e10, "start_time");
  for (const auto& [key, speed] : {std::pair<const char*, double>{"speed", c.speed},
                                   {"moving_car_speed", c.moving_car_speed},
                                   {"traffic_min_speed", c.traffic_min_speed},
                                   {"traffic_max_speed", c.traffic_max_speed}}) {
    bounded(speed, 0.0, kMaxSimulatedSpeed, key);
  }
  for (const auto& [key, length] : {std::pair<const char*, double>{"loop_length", c.loop_length},
                                    {"loop_width", c.loop_width},
                                    {"start_offset", c.start_offset},
                                    {"max_range", c.max_range},
                                    {"sensor_height", c.sensor_height}}) {
    bounded(length, 0.0, kMaxSimulatedLength, key);
  }
  for (const auto& [key, angle] : {std::pair<const char*, double>{"attitude_wobble_deg", c.attitude_wobble_deg},
                                   {"azimuth_noise_deg", c.azimuth_noise_deg},
                                   {"elevation_noise_deg", c.elevation_noise_deg}}) {
    bounded(angle, 0.0, 45.0, key);
  }
  bounded(c.elevation_noise_growth, 0.0, 100.0, "elevation_noise_growth");
  bounded(c.range_noise, 0.0, 100.0, "range_noise");
  bounded(c.doppler_noise, 0.0, 100.0, "doppler_noise");
  for (const auto& [key, db] : {std::pair<const char*, double>{"rcs_noise_db", c.rcs_noise_db},
                                {"object_rcs_spread_db", c.object_rcs_spread_db},
                                {"multipath_loss_db", c.multipath_loss_db}}) {
    bounded(db, 0.0, 200.0, key);
  }
  bounded(c.detection_threshold_db, -200.0, 200.0, "detection_threshold_db");
  // The IMU: up to 2 kHz; noise and biases up to what no working MEMS part exceeds tenfold.
  bounded(c.imu_rate_hz, 0.0, 2000.0, "imu_rate_hz");
  for (const auto& [key, value, high] :
       {std::tuple<const char*, double, double>{"imu_gyro_noise_density", c.imu_gyro_noise_density, 0.1},
        {"imu_accel_noise_density", c.imu_accel_noise_density, 1.0},
        {"imu_gyro_bias_std", c.imu_gyro_bias_std, 1.0},
        {"imu_accel_bias_std", c.imu_accel_bias_std, 10.0},
        {"imu_gyro_bias_random_walk", c.imu_gyro_bias_random_walk, 0.1},
        {"imu_accel_bias_random_walk", c.imu_accel_bias_random_walk, 1.0}}) {
    bounded(value, 0.0, high, key);
  }
  for (const auto& [key, angle] : {std::pair<const char*, double>{"imu_roll_deg", c.imu_roll_deg},
                                   {"imu_pitch_deg", c.imu_pitch_deg},
                                   {"imu_yaw_deg", c.imu_yaw_deg}}) {
    bounded(angle, -180.0, 180.0, key);
  }
  for (const auto& [key, length] :
       {std::pair<const char*, double>{"imu_x", c.imu_x}, {"imu_y", c.imu_y}, {"imu_z", c.imu_z}}) {
    bounded(length, -10.0, 10.0, key);
  }
  bounded(c.imu_clock_offset, -0.5, 0.5, "imu_clock_offset");
}

}  // namespace

void ValidateSimulationConfig(const SimulationConfig& c, const std::string& source) {
  const auto require = [&](bool ok, const std::string& what) {
    if (!ok) throw FileError(source, what);
  };
  SimulationConfig copy = c;
  for (const auto& [key, value] : ConfigFields(copy)) {
    if (const double* number = std::get_if<double*>(&value) ? *std::get_if<double*>(&value) : nullptr) {
      require(std::isfinite(*number), key + " must be a finite number");
    }
  }
  ValidateMagnitudes(c, source);
  require(c.scans >= 1, "scans must be >= 1");
  require(c.corner_radius > 0.0 && c.loop_length > 2.0 * c.corner_radius && c.loop_width > 2.0 * c.corner_radius,
          "loop_length and loop_width must exceed 2 x corner_radius > 0");
  require(c.sensor_height > 0.0, "sensor_height must be > 0");
  require(c.azimuth_fov_deg > 0.0 && c.azimuth_fov_deg <= 90.0, "azimuth_fov_deg must be in (0, 90]");
  require(c.elevation_fov_deg > 0.0 && c.elevation_fov_deg < 90.0, "elevation_fov_deg must be in (0, 90)");
  require(c.min_range >= 0.0 && c.max_range > c.min_range, "need 0 <= min_range < max_range");
  require(c.min_detections >= 1 && c.max_detections >= c.min_detections, "need 1 <= min_detections <= max_detections");
  require(c.max_rays >= 1, "max_rays must be >= 1");
  require(c.clutter_fraction >= 0.0 && c.clutter_fraction < 1.0, "clutter_fraction must be in [0, 1)");
  require(c.rcs_outlier_fraction >= 0.0 && c.rcs_outlier_fraction <= 1.0, "rcs_outlier_fraction must be in [0, 1]");
  require(c.poles >= 0 && c.parked_cars >= 0 && c.moving_cars >= 0, "object counts must be >= 0");
  require(std::abs(c.elevation_bias_deg) < c.elevation_fov_deg, "elevation_bias_deg must be within the field of view");
  for (const auto& [key, angle] : {std::pair<const char*, double>{"mounting_roll_deg", c.mounting_roll_deg},
                                   {"mounting_pitch_deg", c.mounting_pitch_deg},
                                   {"mounting_yaw_deg", c.mounting_yaw_deg}}) {
    require(std::abs(angle) <= 45.0, std::string(key) + " must be within +/-45 deg");
  }
  require(c.rcs_swerling == 0 || c.rcs_swerling == 1 || c.rcs_swerling == 3, "rcs_swerling must be 0, 1 or 3");
  require(c.multipath_probability >= 0.0 && c.multipath_probability <= 1.0, "multipath_probability must be in [0, 1]");
  require(c.scene == "town" || c.scene == "motorway", "scene must be town or motorway");
  require(c.traffic_max_speed >= c.traffic_min_speed, "need traffic_min_speed <= traffic_max_speed");
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

SimulationConfig LoadSimulationConfig(const std::string& path) {
  SimulationConfig config;
  const YAML::Node root = ReadYamlDocument(path, "simulation config");
  if (root.IsNull()) return config;
  if (!root.IsMap()) throw FileError(path, "expected a map of parameters");
  auto fields = ConfigFields(config);
  for (const auto& entry : root) {
    if (!entry.first.IsScalar()) {
      throw FileError(path, entry.first.Mark().line + 1, "a key must be a parameter name");
    }
    const std::string key = entry.first.Scalar();
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
      const auto it = std::find_if(fields.begin(), fields.end(), [&](const auto& field) { return field.first == key; });
      if (it == fields.end()) throw FileError(path, "unknown parameter '" + key + "'");
      std::visit([&](auto* target) { *target = entry.second.as<std::remove_pointer_t<decltype(target)>>(); },
                 it->second);
    } catch (const YAML::Exception& e) {
      throw FileError(path, e.mark.line + 1, "parameter '" + key + "' has the wrong type");
    }
  }
  ValidateSimulationConfig(config, path);
  return config;
}

std::string SimulationConfigToYaml(const SimulationConfig& config) {
  SimulationConfig copy = config;
  std::ostringstream out;
  out.precision(17);
  for (const auto& [key, value] : ConfigFields(copy)) {
    out << key << ": ";
    std::visit([&](auto* target) { out << *target; }, value);
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

namespace {

// imu.txt, imu_extrinsic.txt and imu_biases.txt of docs/design/simulator.md, "The synthetic world".
void WriteSimulatedImu(const std::string& dir, const SimulatedSequence& sequence) {
  namespace fs = std::filesystem;
  WriteFileAtomically((fs::path(dir) / "imu.txt").string(), [&](std::ostream& out) {
    out << "# stamp wx wy wz ax ay az (s, rad/s, m/s^2; the IMU's frame)\n";
    char line[256];
    for (const ImuSample& s : sequence.imu) {
      std::snprintf(line, sizeof(line), "%.9f %.17g %.17g %.17g %.17g %.17g %.17g\n", s.stamp, s.angular_velocity.x(),
                    s.angular_velocity.y(), s.angular_velocity.z(), s.specific_force.x(), s.specific_force.y(),
                    s.specific_force.z());
      out << line;
    }
  });
  WriteFileAtomically((fs::path(dir) / "imu_extrinsic.txt").string(), [&](std::ostream& out) {
    const Eigen::Vector3d& t = sequence.radar_from_imu.translation();
    const Eigen::Quaterniond& q = sequence.radar_from_imu.rotation().quaternion();
    char line[256];
    std::snprintf(line, sizeof(line), "%.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", t.x(), t.y(), t.z(), q.x(), q.y(),
                  q.z(), q.w());
    out << "# x y z qx qy qz qw: T_radar_imu\n" << line;
  });
  WriteFileAtomically((fs::path(dir) / "imu_biases.txt").string(), [&](std::ostream& out) {
    out << "# stamp bgx bgy bgz bax bay baz: the true biases (rad/s, m/s^2), for evaluation only\n";
    char line[256];
    for (std::size_t k = 0; k < sequence.imu.size(); ++k) {
      const ImuBias& b = sequence.imu_bias[k];
      std::snprintf(line, sizeof(line), "%.9f %.9g %.9g %.9g %.9g %.9g %.9g\n", sequence.imu[k].stamp, b.gyro.x(),
                    b.gyro.y(), b.gyro.z(), b.accel.x(), b.accel.y(), b.accel.z());
      out << line;
    }
  });
}

}  // namespace

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
  if (!sequence.imu.empty()) WriteSimulatedImu(dir, sequence);
  WriteFileAtomically((fs::path(dir) / "simulation.yaml").string(), [&](std::ostream& out) {
    out << "# radargauss simulate: the configuration that produced this sequence\n"
        << SimulationConfigToYaml(sequence.config);
  });
}

}  // namespace radargauss
