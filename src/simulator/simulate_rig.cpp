// SPDX-License-Identifier: BSD-3-Clause
// A simulated rig (docs/design/rig.md, "A simulated rig"): one simulation
// per radar over the same drive and world, written as a rig file's folders;
// its config file.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <system_error>

#include "config_keys.hpp"
#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/yaml_file.hpp"
#include "radargauss/io/rig.hpp"
#include "radargauss/simulator/imu_from_reference.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "scene.hpp"

namespace radargauss {

// The drive's and world's keys, and the IMU's (one on the body).
const std::vector<std::string>& RigSharedSimulationKeys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> shared = {"world_seed",
                                       "start_offset",
                                       "scans",
                                       "start_time",
                                       "speed",
                                       "loop_length",
                                       "loop_width",
                                       "corner_radius",
                                       "sensor_height",
                                       "attitude_wobble_deg",
                                       "scene",
                                       "traffic_min_speed",
                                       "traffic_max_speed",
                                       "poles",
                                       "parked_cars",
                                       "moving_cars",
                                       "moving_car_speed",
                                       "object_rcs_spread_db",
                                       "materials"};
    for (const auto& row : SimulationOptionTable()) {
      if (row.name.rfind("imu_", 0) == 0) shared.push_back(row.name);
    }
    return shared;
  }();
  return keys;
}

RigSimulationConfig LoadRigSimulationConfig(const std::string& path) {
  const YAML::Node root = ReadYamlDocument(path, "rig simulation config");
  if (!root.IsMap()) throw FileError(path, "a rig simulation config is a map of world: and radars:");
  for (const auto& entry : root) {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : "";
    if (key != "world" && key != "radars") throw FileError(path, "unknown key '" + key + "' (world, radars)");
  }
  RigSimulationConfig rig;
  if (root["world"]) ApplySimulationKeys(root["world"], path, rig.world, {}, "");
  ValidateSimulationConfig(rig.world, path);
  const YAML::Node radars = root["radars"];
  if (!radars || !radars.IsSequence() || radars.size() == 0) throw FileError(path, "no radars: (a list of radars)");
  if (radars.size() > 16) throw FileError(path, std::to_string(radars.size()) + " radars (at most 16)");
  for (std::size_t i = 0; i < radars.size(); ++i) {
    const YAML::Node radar = radars[i];
    if (!radar.IsMap() || !radar["name"] || !radar["name"].IsScalar() || radar["name"].Scalar().empty()) {
      throw FileError(path, "radar " + std::to_string(i + 1) + " needs a name");
    }
    const std::string name = radar["name"].Scalar();
    for (const auto& [other, unused] : rig.radars) {
      if (other == name) throw FileError(path, "two radars are named '" + name + "'");
    }
    YAML::Node keys = YAML::Clone(radar);
    keys.remove("name");
    SimulationConfig config = rig.world;
    config.seed = rig.world.seed + std::uint32_t(i);
    ApplySimulationKeys(keys, path, config, RigSharedSimulationKeys(),
                        "radar '" + name + "' sets a key of the rig's drive and world (set it under world:)");
    ValidateSimulationConfig(config, path + " (radar '" + name + "')");
    rig.radars.emplace_back(name, config);
  }
  return rig;
}

SimulatedRig SimulateRig(const RigSimulationConfig& config) {
  if (config.radars.empty()) throw DataError("a simulated rig needs a radar");
  const double duration = double(config.world.scans) / config.world.rate_hz;  // s
  SimulatedRig rig;
  for (const auto& [name, radar] : config.radars) {
    SimulationConfig one = radar;
    one.imu_rate_hz = 0.0;  // the body's IMU is simulated once, below
    one.world_seed = config.world.world_seed != 0 ? config.world.world_seed : config.world.seed;
    one.scans = std::max(1, int(std::floor(duration * one.rate_hz + 1e-9)));
    rig.names.push_back(name);
    rig.radars.push_back(Simulate(one));
    rig.body_from_radar.push_back(RadarOnVehicle(one));
  }
  // The body on the true clock, from the first radar's poses.
  const SimulatedSequence& first = rig.radars.front();
  const SE3d radar_from_body = rig.body_from_radar.front().Inverse();
  const simulation::LoopPath path{config.world.loop_length, config.world.loop_width, config.world.corner_radius};
  for (std::size_t k = 0; k < first.ground_truth.size(); ++k) {
    const StampedPose& sample = first.ground_truth[k];
    rig.body.Append(sample.time - first.config.clock_offset, sample.pose * radar_from_body);
    constexpr double kStep = 1e-4;  // s
    const double since_start = double(k) / first.config.rate_hz;
    SE3d before, after;
    Eigen::Vector3d unused;
    simulation::SensorState(first.config, path, since_start - kStep, before, unused);
    simulation::SensorState(first.config, path, since_start + kStep, after, unused);
    const SO3d rotation = (sample.pose * radar_from_body).rotation();
    rig.body_velocity.push_back(rotation.Inverse() * (after.translation() - before.translation()) / (2.0 * kStep));
    rig.body_angular_velocity.push_back((before.rotation().Inverse() * after.rotation()).Log() / (2.0 * kStep));
  }
  if (config.world.imu_rate_hz > 0.0) {  // over the whole drive, its draws seeded after the radars'
    SimulationConfig world = config.world;
    world.seed = config.world.seed + std::uint32_t(config.radars.size());
    SimulatedImu imu = simulation::VehicleImu(world, std::size_t(std::floor(duration * world.imu_rate_hz + 1e-9)) + 1);
    rig.imu = std::move(imu.samples);
    rig.imu_bias = std::move(imu.bias);
    rig.body_from_imu = ImuOnVehicle(world);
  }
  return rig;
}

void WriteSimulatedRig(const std::string& dir, const SimulatedRig& simulated) {
  namespace fs = std::filesystem;
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) throw FileError(dir, "cannot create the output folder: " + error.message());
  Rig rig;
  for (std::size_t r = 0; r < simulated.radars.size(); ++r) {
    WriteSimulatedSequence((fs::path(dir) / simulated.names[r]).string(), simulated.radars[r]);
    RigRadar radar;
    radar.name = simulated.names[r];
    radar.scans.sequence_dir = simulated.names[r];  // beside rig.yaml
    radar.body_from_radar = simulated.body_from_radar[r];
    radar.clock_offset = simulated.radars[r].config.clock_offset;
    rig.radars.push_back(radar);
  }
  WriteRig((fs::path(dir) / "rig.yaml").string(), rig);
  WriteTum((fs::path(dir) / "gt_body_tum.txt").string(), simulated.body);
  if (!simulated.imu.empty()) WriteImuFiles(dir, {simulated.imu, simulated.imu_bias}, simulated.body_from_imu, "body");
  WriteFileAtomically((fs::path(dir) / "twist_body.txt").string(), [&](std::ostream& out) {
    out << "# t vx vy vz wx wy wz: the body's true velocity (m/s) and angular velocity (rad/s), body frame\n";
    out << std::setprecision(12);
    for (std::size_t k = 0; k < simulated.body.size(); ++k) {
      const Eigen::Vector3d& v = simulated.body_velocity[k];
      const Eigen::Vector3d& w = simulated.body_angular_velocity[k];
      out << simulated.body[k].time << ' ' << v.x() << ' ' << v.y() << ' ' << v.z() << ' ' << w.x() << ' ' << w.y()
          << ' ' << w.z() << '\n';
    }
  });
}

}  // namespace radargauss
