// SPDX-License-Identifier: BSD-3-Clause
// A run as an MCAP file that a robotics viewer (Foxglove, RViz through
// rosbag2) opens (docs/design/formats.md, "ROS 2 bags"): the trajectory, the
// reference, the scans registered in the map's frame, the map's Gaussians
// (means with their RCS, and ellipsoids), the loops, and map -> radar as tf.
//
//   radargauss export RUN_FOLDER --mcap run.mcap [--sequence ... for the scans]
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "radargauss/io/mcap.hpp"
#include "radargauss/lie/se3.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

struct RunForViewer {
  std::vector<double> stamps;  // s, one per pose
  std::vector<SE3d> poses;     // T_map_radar
  std::vector<double> reference_stamps;
  std::vector<SE3d> reference;                                     // T_map_radar of the reference, when there is one
  std::vector<RadarScan> scans;                                    // empty, or one per pose (registered by it)
  GaussianMap map;                                                 // empty when the run has none
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> loops;  // the two keyframes' positions
};

// An ellipsoid drawn beyond this many standard deviations says nothing.
constexpr double kMaxEllipsoidSigma = 10.0;

struct RunMcapOptions {
  double ellipsoid_sigma = 2.0;        // an ellipsoid's semi-axes: this many standard deviations
  std::size_t max_ellipsoids = 50000;  // the most populated Gaussians beyond this are left out
  McapWriterOptions mcap;
};

// Topics: /radar/pose (geometry_msgs/msg/PoseStamped) and /tf per pose,
// /radar/registered (sensor_msgs/msg/PointCloud2, the scan in the map's
// frame with doppler and rcs) per scan, then once at the end /trajectory and
// /reference/trajectory (nav_msgs/msg/Path), /map/gaussians (PointCloud2 of
// the means with rcs_median and members), /map/ellipsoids and /loops
// (visualization_msgs/msg/MarkerArray). Written atomically.
void WriteRunMcap(const std::string& path, const RunForViewer& run, const RunMcapOptions& options = {});

// A results folder of odometry, slam or relocalize: its trajectory
// (slam.tum, else odometry.tum, else relocalization.tum), map.rgm when
// present, and the accepted loops (loops.csv with keyframes.csv). Throws
// DataError naming what is missing or malformed.
RunForViewer ReadRunFolder(const std::string& folder);

}  // namespace radargauss
