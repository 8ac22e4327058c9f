// SPDX-License-Identifier: BSD-3-Clause
// Simulated rigs for the tests of a rig's odometry and calibration: corner
// radars, their configs, the true rig and the errors of a calibrated one.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <vector>

#include <Eigen/Core>

#include "radargauss/io/rig.hpp"
#include "radargauss/odometry/rig_odometry.hpp"
#include "radargauss/simulator/simulator.hpp"

namespace radargauss::testing {

inline SimulationConfig Corner(double x, double y, double yaw_deg) {
  SimulationConfig c;
  c.mounting_x = x;
  c.mounting_y = y;
  c.mounting_z = 0.5;
  c.mounting_yaw_deg = yaw_deg;
  c.azimuth_fov_deg = 75.0;
  c.max_range = 80.0;
  c.min_detections = 80;
  c.max_detections = 200;
  return c;
}

// Four corner radars scanning together (10 Hz, no clock offsets).
inline RigSimulationConfig FourCorners(int scans) {
  RigSimulationConfig rig;
  rig.world.scans = scans;
  rig.radars = {{"front_left", Corner(3.4, 0.9, 45.0)},
                {"front_right", Corner(3.4, -0.9, -45.0)},
                {"rear_left", Corner(-0.9, 0.9, 135.0)},
                {"rear_right", Corner(-0.9, -0.9, -135.0)}};
  for (std::size_t r = 0; r < rig.radars.size(); ++r) rig.radars[r].second.seed = std::uint32_t(10 + r);
  return rig;
}

// A front radar at 10 Hz and a front corner at 20 Hz on its own clock.
inline RigSimulationConfig FrontAndFastCorner(int scans) {
  RigSimulationConfig config;
  config.world.scans = scans;
  SimulationConfig front;
  front.mounting_x = 3.7;
  front.mounting_z = 0.5;
  SimulationConfig corner = Corner(3.4, 0.9, 45.0);
  corner.rate_hz = 20.0;
  corner.clock_offset = 0.012;
  config.radars = {{"front", front}, {"front_left", corner}};
  return config;
}

// The simulated rig's true mountings and clocks.
inline Rig TrueRig(const RigSimulationConfig& config, const SimulatedRig& simulated) {
  Rig truth;
  for (std::size_t r = 0; r < simulated.radars.size(); ++r) {
    RigRadar radar;
    radar.name = config.radars[r].first;
    radar.body_from_radar = simulated.body_from_radar[r];
    radar.clock_offset = config.radars[r].second.clock_offset;
    truth.radars.push_back(radar);
  }
  return truth;
}

// The second radar's calibration errors against the truth: rotation (deg), translation (m), clock (s).
inline Eigen::Vector3d CalibrationErrors(const Rig& truth, const Rig& calibrated) {
  const RigRadar &radar = calibrated.radars[1], &true_radar = truth.radars[1];
  return Eigen::Vector3d(
      (true_radar.body_from_radar.rotation().Inverse() * radar.body_from_radar.rotation()).Log().norm() * 180.0 / M_PI,
      (radar.body_from_radar.translation() - true_radar.body_from_radar.translation()).norm(),
      std::abs(radar.clock_offset - true_radar.clock_offset));
}

// Every radar's scans into `odometry` on the body's clock (stamps minus the
// given clock offsets), as ForEachRigScan gives them: a tie to the radar first listed.
inline void RegisterOnTheBodysClock(RigOdometry& odometry, const SimulatedRig& rig,
                                    const std::vector<double>& clock_offsets) {
  std::vector<std::tuple<double, std::size_t, std::size_t>> order;  // body stamp, radar, scan
  for (std::size_t r = 0; r < rig.radars.size(); ++r) {
    for (std::size_t k = 0; k < rig.radars[r].scans.size(); ++k) {
      order.emplace_back(rig.radars[r].scans[k].timestamp - clock_offsets[r], r, k);
    }
  }
  std::sort(order.begin(), order.end());
  for (const auto& [stamp, r, k] : order) {
    RadarScan scan = rig.radars[r].scans[k];
    scan.timestamp = stamp;
    odometry.Register(r, scan);
  }
  odometry.Finish();
}

// As above, at the simulated radars' true clock offsets.
inline void RegisterOnTheBodysClock(RigOdometry& odometry, const SimulatedRig& rig, const RigSimulationConfig& config) {
  std::vector<double> offsets;
  for (const auto& radar : config.radars) offsets.push_back(radar.second.clock_offset);
  RegisterOnTheBodysClock(odometry, rig, offsets);
}

// The mountings of `rig`'s radars (T_body_radar), in its order.
inline std::vector<SE3d> MountingsOf(const Rig& rig) {
  std::vector<SE3d> mountings;
  for (const RigRadar& radar : rig.radars) mountings.push_back(radar.body_from_radar);
  return mountings;
}

// `truth` with its second radar given off: 2 deg, 5 cm and 20 ms.
inline Rig GivenOff(const Rig& truth) {
  Rig given = truth;
  given.radars[1].body_from_radar =
      SE3d(truth.radars[1].body_from_radar.rotation() *
               SO3d::Exp(Eigen::Vector3d(1.0, -1.0, 1.0).normalized() * (2.0 * M_PI / 180.0)),
           truth.radars[1].body_from_radar.translation() + 0.05 * Eigen::Vector3d(-1.0, 1.0, 1.0).normalized());
  given.radars[1].clock_offset += 0.020;
  return given;
}

}  // namespace radargauss::testing
