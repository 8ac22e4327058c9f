// SPDX-License-Identifier: BSD-3-Clause
// The map cloud: the static points of a sequence (Doppler ego-velocity
// inliers) merged into the world frame with the reference poses. Every point
// keeps the index of its scan, so its radar pose is known when incidence
// vectors are formed.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "radargauss/core/doppler.hpp"
#include "radargauss/io/sequence.hpp"
#include "radargauss/lie/se3.hpp"

namespace radargauss {

struct MapCloud {
  std::vector<Eigen::Vector3d> points;  // world frame
  std::vector<double> rcs;              // dBsm (0 when the sequence has none)
  std::vector<std::uint32_t> scan;      // index into poses
  std::vector<SE3d> poses;              // T_world_radar of each scan of the sequence
  bool has_rcs = false;
};

struct MapCloudOptions {
  bool doppler_filter = true;  // keep only ego-velocity inliers (needs Doppler)
  EgoVelocityOptions ego_velocity;
};

struct MapCloudStats {
  std::size_t scans = 0;
  std::size_t scans_without_ego_velocity = 0;  // filter failed: the scan adds nothing
  std::size_t points_in = 0;
  std::size_t points_static = 0;
};

// Needs a pose T_world_radar per scan (a ground truth). Scans whose ego
// velocity fails contribute no points and are counted. Without Doppler in
// the scans the filter is skipped (every point kept).
MapCloud BuildMapCloud(const std::vector<RadarScan>& scans, const std::vector<SE3d>& poses,
                       const MapCloudOptions& options = {}, MapCloudStats* stats = nullptr);
inline MapCloud BuildMapCloud(const Sequence& sequence, const MapCloudOptions& options = {},
                              MapCloudStats* stats = nullptr) {
  return BuildMapCloud(sequence.scans, sequence.poses, options, stats);
}

}  // namespace radargauss
