// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/imu.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"

namespace radargauss {

namespace {

// A text file of kMaxImuSamples lines of seven numbers with their spaces.
constexpr std::size_t kMaxImuFileBytes = kMaxImuSamples * 160;

bool Blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

}  // namespace

std::vector<ImuSample> ReadImuFile(const std::string& path) {
  const std::string bytes = ReadFileBytes(path, "IMU file", kMaxImuFileBytes);
  std::vector<ImuSample> samples;
  std::size_t line_number = 0;
  for (std::size_t begin = 0; begin < bytes.size();) {
    std::size_t end = bytes.find('\n', begin);
    if (end == std::string::npos) end = bytes.size();
    ++line_number;
    std::string line = bytes.substr(begin, end - begin);
    begin = end + 1;
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    double v[7];
    std::size_t count = 0;
    const char* cursor = line.c_str();
    while (true) {
      while (Blank(*cursor)) ++cursor;
      if (*cursor == '\0') break;
      char* after = nullptr;
      errno = 0;
      const double value = std::strtod(cursor, &after);
      if (after == cursor || !(*after == '\0' || Blank(*after))) {
        throw FileError(path, line_number,
                        "not a number: '" + std::string(cursor, std::strcspn(cursor, " \t\r")) + "'");
      }
      if (count < 7) v[count] = value;
      ++count;
      cursor = after;
    }
    if (count != 7) {
      throw FileError(path, line_number,
                      "expected 7 columns (stamp wx wy wz ax ay az), found " + std::to_string(count));
    }
    if (!std::all_of(v, v + 7, [](double x) { return std::isfinite(x); })) {
      throw FileError(path, line_number, "non-finite value");
    }
    const ImuSample sample{v[0], Eigen::Vector3d(v[1], v[2], v[3]), Eigen::Vector3d(v[4], v[5], v[6])};
    const std::string fault = ImuSampleFault(sample);
    if (!fault.empty()) throw FileError(path, line_number, fault);
    if (!samples.empty() && !(v[0] > samples.back().stamp)) {
      throw FileError(path, line_number, "stamp does not increase");
    }
    if (samples.size() == kMaxImuSamples) {
      throw FileError(path, "more than " + std::to_string(kMaxImuSamples) + " IMU samples");
    }
    samples.push_back(sample);
  }
  if (samples.empty()) throw FileError(path, "no IMU sample (lines 'stamp wx wy wz ax ay az')");
  return samples;
}

std::string ImuSampleFault(const ImuSample& sample) {
  const auto text = [](double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%g", x);
    return std::string(buffer);
  };
  if (!std::isfinite(sample.stamp) || !sample.angular_velocity.allFinite() || !sample.specific_force.allFinite()) {
    return "non-finite value";
  }
  const double rate = sample.angular_velocity.cwiseAbs().maxCoeff();
  const double force = sample.specific_force.cwiseAbs().maxCoeff();
  if (rate > kMaxPhysicalAngularRate) {
    return "angular rate " + text(rate) + " rad/s is past any IMU's " + text(kMaxPhysicalAngularRate);
  }
  if (force > kMaxPhysicalSpecificForce) {
    return "specific force " + text(force) + " m/s^2 is past any IMU's " + text(kMaxPhysicalSpecificForce);
  }
  return {};
}

ImuScreening ScreenImuSamples(std::vector<ImuSample>& samples, const ImuNoise& imu) {
  ImuScreening screening;
  const auto within = [&](const ImuSample& s) {
    return s.angular_velocity.cwiseAbs().maxCoeff() <= imu.gyro_range &&
           s.specific_force.cwiseAbs().maxCoeff() <= imu.accel_range;
  };
  std::vector<ImuSample> kept;
  kept.reserve(samples.size());
  for (const ImuSample& s : samples) {
    if (within(s)) kept.push_back(s);
  }
  screening.beyond_range = samples.size() - kept.size();
  // A spike on either sensor: far from both neighbours, which agree with each other.
  const auto spike = [](const Eigen::Vector3d& before, const Eigen::Vector3d& x, const Eigen::Vector3d& after,
                        double range) {
    const double jump = 0.25 * range;
    return (x - before).norm() > jump && (x - after).norm() > jump && (after - before).norm() < 0.5 * jump;
  };
  samples.clear();
  for (std::size_t k = 0; k < kept.size(); ++k) {
    const bool inner = k > 0 && k + 1 < kept.size();
    if (inner &&
        (spike(kept[k - 1].angular_velocity, kept[k].angular_velocity, kept[k + 1].angular_velocity, imu.gyro_range) ||
         spike(kept[k - 1].specific_force, kept[k].specific_force, kept[k + 1].specific_force, imu.accel_range))) {
      ++screening.spikes;
      continue;
    }
    samples.push_back(kept[k]);
  }
  return screening;
}

const OptionTable<ImuNoise>& ImuNoiseOptionTable() {
  using O = ImuNoise;
  static const OptionTable<O> table = {
      RADARGAUSS_OPTION(O, "gyro_noise_density", gyro_noise_density)
          .In(1e-7, 0.1)
          .Unit("rad/s/sqrt(Hz)")
          .Help("the gyro's white noise, as its datasheet gives it"),
      RADARGAUSS_OPTION(O, "accel_noise_density", accel_noise_density)
          .In(1e-6, 1.0)
          .Unit("m/s^2/sqrt(Hz)")
          .Help("the accelerometer's white noise"),
      RADARGAUSS_OPTION(O, "gyro_bias_random_walk", gyro_bias_random_walk)
          .In(1e-9, 0.1)
          .Unit("rad/s^2/sqrt(Hz)")
          .Help("the gyro bias's random walk"),
      RADARGAUSS_OPTION(O, "accel_bias_random_walk", accel_bias_random_walk)
          .In(1e-9, 1.0)
          .Unit("m/s^3/sqrt(Hz)")
          .Help("the accelerometer bias's random walk"),
      RADARGAUSS_OPTION(O, "gyro_range", gyro_range)
          .In(0.1, kMaxPhysicalAngularRate)
          .Unit("rad/s")
          .Help("the gyro's measuring range; a sample beyond it is dropped (34.9: 2000 deg/s)"),
      RADARGAUSS_OPTION(O, "accel_range", accel_range)
          .In(1.0, kMaxPhysicalSpecificForce)
          .Unit("m/s^2")
          .Help("the accelerometer's measuring range; a sample beyond it is dropped (156.9: 16 g)"),
  };
  return table;
}

ImuSummary SummariseImu(const std::vector<ImuSample>& samples) {
  if (samples.empty()) throw std::invalid_argument("SummariseImu: no samples");
  ImuSummary summary;
  summary.samples = samples.size();
  summary.start = samples.front().stamp;
  summary.end = samples.back().stamp;
  std::vector<double> intervals;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    summary.mean_angular_velocity += samples[k].angular_velocity / double(samples.size());
    summary.mean_specific_force += samples[k].specific_force / double(samples.size());
    if (k > 0) intervals.push_back(samples[k].stamp - samples[k - 1].stamp);
  }
  if (intervals.empty()) return summary;
  summary.max_gap = *std::max_element(intervals.begin(), intervals.end());
  std::vector<double> sorted = intervals;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = sorted[sorted.size() / 2];
  summary.rate_hz = 1.0 / median;
  summary.gaps =
      std::size_t(std::count_if(intervals.begin(), intervals.end(), [&](double dt) { return dt > 3.0 * median; }));
  return summary;
}

}  // namespace radargauss
