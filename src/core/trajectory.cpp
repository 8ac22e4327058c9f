// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/core/trajectory.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"

namespace radargauss {

namespace {

void RequireIncreasing(double previous, double time) {
  if (!std::isfinite(time)) throw std::invalid_argument("trajectory time is not finite");
  if (!(time > previous)) {
    throw std::invalid_argument("trajectory times must strictly increase (" + std::to_string(previous) + " then " +
                                std::to_string(time) + ")");
  }
}

// Parses one whole token as a double; false if it is not entirely a number.
bool ParseDouble(const std::string& token, double& value) {
  const char* first = token.data();
  const char* last = token.data() + token.size();
  const auto [end, error] = std::from_chars(first, last, value);
  return error == std::errc() && end == last;
}

}  // namespace

Trajectory::Trajectory(std::vector<StampedPose> poses) : poses_(std::move(poses)) {
  for (std::size_t i = 0; i < poses_.size(); ++i) {
    RequireIncreasing(i == 0 ? -INFINITY : poses_[i - 1].time, poses_[i].time);
  }
}

void Trajectory::Append(double time, const SE3d& pose) {
  RequireIncreasing(poses_.empty() ? -INFINITY : poses_.back().time, time);
  poses_.push_back({time, pose});
}

std::optional<SE3d> Trajectory::Interpolate(double time) const {
  if (poses_.empty() || !(time >= StartTime()) || !(time <= EndTime())) return std::nullopt;
  const auto after = std::lower_bound(poses_.begin(), poses_.end(), time,
                                      [](const StampedPose& sample, double t) { return sample.time < t; });
  if (after->time == time) return after->pose;
  const StampedPose& before = *(after - 1);
  const double s = (time - before.time) / (after->time - before.time);
  // slerp: R_a Exp(s Log(R_a^-1 R_b)); linear translation.
  const Eigen::Vector3d relative_rotation = (before.pose.rotation().Inverse() * after->pose.rotation()).Log();
  return SE3d(before.pose.rotation() * SO3d::Exp(s * relative_rotation),
              (1.0 - s) * before.pose.translation() + s * after->pose.translation());
}

Trajectory Trajectory::RightMultiplied(const SE3d& frame_to_new) const {
  Trajectory result;
  result.poses_.reserve(poses_.size());
  for (const StampedPose& sample : poses_) {
    result.poses_.push_back({sample.time, sample.pose * frame_to_new});
  }
  return result;
}

Trajectory ReadTum(const std::string& path) {
  std::istringstream in(ReadFileBytes(path, "TUM trajectory"));
  Trajectory trajectory;
  std::string line;
  std::size_t line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream tokens(line);
    std::array<double, 8> v{};
    std::string token;
    std::size_t count = 0;
    while (tokens >> token) {
      if (count < v.size() && !ParseDouble(token, v[count])) {
        throw FileError(path, line_number, "not a number: '" + token + "'");
      }
      ++count;
    }
    if (count != v.size()) {
      throw FileError(path, line_number, "expected 8 columns (t x y z qx qy qz qw), found " + std::to_string(count));
    }
    for (const double value : v) {
      if (!std::isfinite(value)) throw FileError(path, line_number, "non-finite value");
    }
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > kTumQuaternionNormTolerance) {
      throw FileError(path, line_number, "quaternion norm " + std::to_string(q.norm()) + " is not 1");
    }
    if (!trajectory.empty() && !(v[0] > trajectory.EndTime())) {
      throw FileError(path, line_number, "time does not increase");
    }
    trajectory.Append(v[0], SE3d(SO3d(q), Eigen::Vector3d(v[1], v[2], v[3])));
  }
  if (in.bad()) throw FileError(path, "read error");
  return trajectory;
}

void WriteTum(const std::string& path, const Trajectory& trajectory, TumPrecision precision) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    char buffer[256];
    for (const StampedPose& sample : trajectory) {
      const Eigen::Vector3d& t = sample.pose.translation();
      const Eigen::Quaterniond& q = sample.pose.rotation().quaternion();
      const char* format = precision == TumPrecision::kRoundTrip ? "%.9f %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n"
                                                                 : "%.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n";
      std::snprintf(buffer, sizeof(buffer), format, sample.time, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
      out << buffer;
    }
  });
}

}  // namespace radargauss
