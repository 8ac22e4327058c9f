// SPDX-License-Identifier: BSD-3-Clause
// Core data types: a radar detection and a radar scan.
// Frames, units and the Doppler sign are those of radargauss/conventions.hpp.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace radargauss {

// Per-detection measurement standard deviations, when the sensor reports them
// (ARS548: range_std, azimuth_std, elevation_std, doppler_std).
struct MeasurementStd {
  float range = 0.0f;      // m
  float azimuth = 0.0f;    // rad
  float elevation = 0.0f;  // rad
  float doppler = 0.0f;    // m/s
};

// One radar detection in the radar frame.
struct RadarPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // m, radar frame
  double doppler = 0.0;                                // m/s, positive receding
  double rcs = 0.0;                                    // dBsm
  std::optional<MeasurementStd> std_dev;               // absent if not reported
};

// One radar scan: the detections of one measurement cycle.
struct RadarScan {
  double timestamp = 0.0;  // s
  std::vector<RadarPoint> points;
  // Whether the source had these fields; when false the values are 0.
  bool has_doppler = false;
  bool has_rcs = false;
};

// Throws DataError naming `source` when a point has a non-finite position,
// Doppler, RCS or std, or a negative std. An empty scan is valid data here;
// stages that need points check for that themselves.
void ValidateScan(const RadarScan& scan, const std::string& source);

// Lowers every point's elevation by `angle` (rad), keeping its range and
// azimuth: removes a radar's elevation bias (docs/design/simulator.md, "The faults of
// real radars").
void LowerElevations(RadarScan& scan, double angle);

}  // namespace radargauss
