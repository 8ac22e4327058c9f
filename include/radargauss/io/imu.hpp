// SPDX-License-Identifier: BSD-3-Clause
// An IMU beside the radar (docs/design/formats.md, "Data in and out"): samples of
// angular rate and specific force in the IMU's frame, read from a text file
// or a bag; the IMU's noise as datasheet figures; a file's summary.
//
//   # stamp wx wy wz ax ay az     (s on the scans' clock, rad/s, m/s^2)
//   1702450000.000 0.001 -0.002 0.010 0.05 -0.02 9.81
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/lie/se3.hpp"
#include "radargauss/core/options.hpp"

namespace radargauss {

struct ImuSample {
  double stamp = 0.0;                                          // s
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // rad/s, the IMU's frame
  Eigen::Vector3d specific_force = Eigen::Vector3d::Zero();    // m/s^2, the IMU's frame (gravity's reaction included)
};

// An IMU's biases: what its gyro and accelerometer read beyond the truth.
struct ImuBias {
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   // rad/s
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  // m/s^2
};

// Gravity's magnitude; a gravity-aligned world has it along -z.
constexpr double kGravity = 9.81;  // m/s^2

// A file holds at most this many samples: an hour at 1 kHz with room to spare.
constexpr std::size_t kMaxImuSamples = std::size_t(4) << 20;

// No IMU reads beyond these (a thousand times a consumer part's range): a
// value past them is garbage or another unit, refused where it is read.
constexpr double kMaxPhysicalAngularRate = 1e4;    // rad/s
constexpr double kMaxPhysicalSpecificForce = 1e5;  // m/s^2

// The samples of a text file of lines `stamp wx wy wz ax ay az` (`#`
// comments, blank lines skipped). Throws DataError naming the file and line
// for a line without exactly seven numbers, a value that is not finite or
// past the physical limits above, a stamp that does not increase, no sample
// at all, or more than kMaxImuSamples.
std::vector<ImuSample> ReadImuFile(const std::string& path);

// Empty when `sample`'s values are finite and within the physical limits;
// otherwise why not ("angular rate 1e+300 rad/s is past any IMU's 10000").
std::string ImuSampleFault(const ImuSample& sample);

// The IMU's noise, continuous time, as a datasheet gives it; the defaults are
// a consumer MEMS part's (a BMI088-like gyro at 0.014 deg/s/sqrt(Hz), an
// accelerometer at 150 ug/sqrt(Hz)).
struct ImuNoise {
  double gyro_noise_density = 2.4e-4;      // rad/s/sqrt(Hz)
  double accel_noise_density = 1.5e-3;     // m/s^2/sqrt(Hz)
  double gyro_bias_random_walk = 2.0e-5;   // rad/s^2/sqrt(Hz)
  double accel_bias_random_walk = 3.0e-4;  // m/s^3/sqrt(Hz)
  // The measuring ranges (a MEMS part's widest: 2000 deg/s, 16 g); a
  // sample beyond them is no measurement (ScreenImuSamples).
  double gyro_range = 34.9;    // rad/s
  double accel_range = 156.9;  // m/s^2
};
// Its options (options.hpp).
const OptionTable<ImuNoise>& ImuNoiseOptionTable();

// What ScreenImuSamples dropped.
struct ImuScreening {
  std::size_t beyond_range = 0;  // a value past the IMU's range on any axis
  std::size_t spikes = 0;        // isolated: far from both neighbours, which agree
};

// Drops from `samples` those beyond `imu`'s ranges, then isolated spikes: a
// sample whose gyro (accelerometer) differs from both neighbours by more
// than a quarter of the range while they differ from each other by less
// than an eighth (one glitched sample, not motion: docs/design/formats.md, "Bounds on input").
ImuScreening ScreenImuSamples(std::vector<ImuSample>& samples, const ImuNoise& imu);

// What `info` says of an IMU: its span, rate and gaps, and the mean specific
// force (about 9.81 m/s^2 along the IMU's up at rest or at constant velocity).
struct ImuSummary {
  std::size_t samples = 0;
  double start = 0.0, end = 0.0;  // s
  double rate_hz = 0.0;           // 1 / the median interval
  double max_gap = 0.0;           // s: the longest interval
  std::size_t gaps = 0;           // intervals over 3x the median
  Eigen::Vector3d mean_angular_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_specific_force = Eigen::Vector3d::Zero();
};
// Throws std::invalid_argument for no samples.
ImuSummary SummariseImu(const std::vector<ImuSample>& samples);

}  // namespace radargauss
