// SPDX-License-Identifier: BSD-3-Clause
// Timestamped trajectories of poses T_world_frame, with interpolation and TUM
// file I/O ("t x y z qx qy qz qw", the format evo reads).
// Invariant of Trajectory: timestamps strictly increase.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "radargauss/lie/se3.hpp"

namespace radargauss {

struct StampedPose {
  double time = 0.0;  // s
  SE3d pose;          // T_world_frame
};

class Trajectory {
 public:
  Trajectory() = default;
  // Throws std::invalid_argument if times are not finite and strictly increasing.
  explicit Trajectory(std::vector<StampedPose> poses);

  // Throws std::invalid_argument if `time` is not finite and after EndTime().
  void Append(double time, const SE3d& pose);

  // The pose at `time`: slerp on rotation and linear on translation between
  // the two bracketing samples; exact at samples; std::nullopt outside
  // [StartTime(), EndTime()] or when empty.
  std::optional<SE3d> Interpolate(double time) const;

  // Every pose right-multiplied by `frame_to_new`: with T_world_body samples
  // and an extrinsic T_body_radar, the result holds T_world_radar.
  Trajectory RightMultiplied(const SE3d& frame_to_new) const;

  std::size_t size() const { return poses_.size(); }
  bool empty() const { return poses_.empty(); }
  const StampedPose& operator[](std::size_t i) const { return poses_[i]; }
  std::vector<StampedPose>::const_iterator begin() const { return poses_.begin(); }
  std::vector<StampedPose>::const_iterator end() const { return poses_.end(); }
  double StartTime() const { return poses_.front().time; }  // requires !empty()
  double EndTime() const { return poses_.back().time; }     // requires !empty()

 private:
  std::vector<StampedPose> poses_;
};

// Largest accepted deviation of a TUM quaternion's norm from 1 (files print
// quaternions with few decimals; the quaternion is normalised after the check).
inline constexpr double kTumQuaternionNormTolerance = 1e-3;

// Reads a TUM file. Blank lines and lines starting with '#' are skipped.
// Throws DataError "<path>:<line>: <fault>" for a missing file, a line without
// exactly 8 numeric columns, a non-finite value, a quaternion whose norm is
// off by more than kTumQuaternionNormTolerance, or a non-increasing time.
Trajectory ReadTum(const std::string& path);

// Writes a TUM file with 9 decimals (kRoundTrip: the pose numbers with 17
// significant digits, which read back to the same doubles, as the
// localisation results are written for comparison), through a temporary
// file renamed into place. Throws DataError if it cannot write.
enum class TumPrecision { kNineDecimals, kRoundTrip };
void WriteTum(const std::string& path, const Trajectory& trajectory,
              TumPrecision precision = TumPrecision::kNineDecimals);

}  // namespace radargauss
