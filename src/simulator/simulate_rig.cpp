// SPDX-License-Identifier: BSD-3-Clause
// A simulated rig (docs/design/rig.md, "A simulated rig"): one simulation
// per radar over the same drive and world, written as a rig file's folders.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <system_error>

#include "radargauss/core/error.hpp"
#include "radargauss/io/rig.hpp"
#include "radargauss/simulator/simulator.hpp"

namespace radargauss {

namespace {

constexpr double kDegree = M_PI / 180.0;

SE3d MountingOf(const SimulationConfig& config) {
  return SE3d(SO3d::Exp(Eigen::Vector3d(0.0, 0.0, config.mounting_yaw_deg * kDegree)) *
                  SO3d::Exp(Eigen::Vector3d(0.0, config.mounting_pitch_deg * kDegree, 0.0)) *
                  SO3d::Exp(Eigen::Vector3d(config.mounting_roll_deg * kDegree, 0.0, 0.0)),
              Eigen::Vector3d(config.mounting_x, config.mounting_y, config.mounting_z));
}

}  // namespace

SimulatedRig SimulateRig(const RigSimulationConfig& config) {
  if (config.radars.empty()) throw DataError("a simulated rig needs a radar");
  const double duration = double(config.world.scans) / config.world.rate_hz;  // s
  SimulatedRig rig;
  for (const auto& [name, radar] : config.radars) {
    SimulationConfig one = radar;
    one.world_seed = config.world.world_seed != 0 ? config.world.world_seed : config.world.seed;
    one.scans = std::max(1, int(std::floor(duration * one.rate_hz + 1e-9)));
    rig.names.push_back(name);
    rig.radars.push_back(Simulate(one));
    rig.body_from_radar.push_back(MountingOf(one));
  }
  // The body on the true clock, from the first radar's poses.
  const SimulatedSequence& first = rig.radars.front();
  const SE3d radar_from_body = rig.body_from_radar.front().Inverse();
  for (const StampedPose& sample : first.ground_truth) {
    rig.body.Append(sample.time - first.config.clock_offset, sample.pose * radar_from_body);
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
}

}  // namespace radargauss
