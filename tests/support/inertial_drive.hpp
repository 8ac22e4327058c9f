// SPDX-License-Identifier: BSD-3-Clause
// The simulated drive the radar-inertial tests share: the demo world (its
// attitude wobble and elevation noise) with a MEMS IMU at 200 Hz, simulated
// once per length and kept for the test binary's life.
#pragma once

#include <map>
#include <memory>

#include "radargauss/simulator/simulator.hpp"

namespace radargauss::testing {

// `scans` scans at 10 Hz: 200 are 20 s with one corner, 300 are 30 s with two.
inline const SimulatedSequence& DemoDriveWithImu(int scans) {
  static std::map<int, std::unique_ptr<SimulatedSequence>> drives;
  std::unique_ptr<SimulatedSequence>& drive = drives[scans];
  if (!drive) {
    SimulationConfig config;
    config.scans = scans;
    config.imu_rate_hz = 200.0;
    drive = std::make_unique<SimulatedSequence>(Simulate(config));
  }
  return *drive;
}

}  // namespace radargauss::testing
