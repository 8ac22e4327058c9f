// SPDX-License-Identifier: BSD-3-Clause
// A sequence: ordered radar scans, the reference trajectory of the radar and
// the extrinsic that relates it to the ground-truth frame. Sources:
//   (a) the Snail-Radar layout  <dir>/ars548/points/<secs>.<nsecs>.pcd
//   (b) any folder of PCD files (or KITTI-style .bin files with a layout)
//   (c) a ROS1 bag topic of sensor_msgs/PointCloud2
// plus a TUM ground truth. Scans are matched to poses by timestamp
// (interpolated); scans outside the trajectory's time span are skipped and
// counted.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "radargauss/io/field_mapping.hpp"
#include "radargauss/lie/se3.hpp"
#include "radargauss/core/trajectory.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

struct SequenceOptions {
  std::string sequence_dir;  // (a) or (b)
  std::string bag;           // (c), with topic
  std::string topic;
  std::string ground_truth;  // TUM file, or BAG:/topic[:child_frame] of a ROS 2 bag; empty: scans without poses
  // "auto" (default): snail-20231213 when the ground-truth file name contains
  // "xt32" (Snail-Radar's utm50r_T_xt32.txt), else identity. Or a preset name
  // (identity, snail-20231213), or a file holding "x y z qx qy qz qw"
  // = T_gt_radar.
  std::string extrinsic = "auto";
  std::string bin_layout = "vod";  // record layout of .bin folders
  FieldMapping fields;
  double elevation_bias_deg = 0.0;  // removed from every point's elevation (LowerElevations)
};

struct Sequence {
  std::string layout;                     // snail-radar, pcd-folder, bin-folder, rosbag
  std::vector<RadarScan> scans;           // time order; with ground truth: matched scans only
  std::vector<std::string> scan_sources;  // file (or bag message) of each scan
  std::vector<SE3d> poses;                // T_world_radar of each scan; empty without ground truth
  Trajectory trajectory;                  // ground truth times extrinsic: T_world_radar samples
  SE3d extrinsic;                         // T_gt_radar
  std::size_t total_scans = 0;            // scans read
  std::size_t skipped_scans = 0;          // outside the trajectory's time span
};

// Throws DataError (one line naming the file and fault) on any bad input.
Sequence LoadSequence(const SequenceOptions& options);

// LoadSequence's scans one at a time, in time order, without holding them
// (a long drive in bounded memory): each with its elevation bias removed and
// its source (file, or BAG:TOPIC#index); `visit` may move the scan away, and
// returns false to read no more. The ground truth is not read. A scan whose
// time does not increase is a DataError when it is reached. Returns the
// layout (Sequence::layout).
std::string ForEachScan(const SequenceOptions& options,
                        const std::function<bool(RadarScan&, const std::string&)>& visit);

// T_xt32_ars548 of the Snail-Radar 2023-12-13 sequences (docs/design/formats.md, "Data in and out").
SE3d SnailRadar20231213Extrinsic();

// A ground-truth TUM file as T_world_radar samples (times the extrinsic
// T_gt_radar), as LoadSequence reads it; or "BAG:/topic[:child_frame]", the
// poses of a ROS 2 bag's topic (ReadBagPoses). Throws DataError for a bad
// file or fewer than 2 poses.
Trajectory ReadRadarTrajectory(const std::string& ground_truth, const SE3d& extrinsic);
// Resolves SequenceOptions::extrinsic; throws DataError for an unknown preset
// or a malformed file.
SE3d ResolveExtrinsic(const std::string& spec, const std::string& ground_truth_path);
// A sensor's mounting on its vehicle is within this of the vehicle's origin.
constexpr double kMaxLeverArm = 1000.0;  // m

// The pose of a file of one line `x y z qx qy qz qw` (`#` comments): an
// extrinsic such as T_gt_radar or T_radar_imu. Throws DataError naming the
// file for a word that is not a number, a value that is not finite, a
// quaternion that is not unit or a translation past kMaxLeverArm.
SE3d ReadExtrinsicFile(const std::string& path);

// How well an extrinsic is known, as its file may state it on a line after
// the pose: `std <rotation deg> <translation m> <clock offset s>` (each std
// about the pose given; 0: exact).
struct ExtrinsicAccuracy {
  double rotation_deg = 0.0;
  double translation = 0.0;   // m
  double clock_offset = 0.0;  // s
};
struct StatedExtrinsic {
  SE3d pose;
  std::optional<ExtrinsicAccuracy> accuracy;  // none: the file does not say
};
// ReadExtrinsicFile's pose with the stated accuracy; a `std` line that is
// not three finite numbers of at most 180 deg, kMaxLeverArm m and 1 s, none
// negative, is a DataError naming the file.
StatedExtrinsic ReadStatedExtrinsicFile(const std::string& path);

}  // namespace radargauss
