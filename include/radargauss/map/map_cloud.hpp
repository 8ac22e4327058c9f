// SPDX-License-Identifier: BSD-3-Clause
// The map cloud: the static points of a sequence (Doppler ego-velocity
// inliers) merged into the world frame with the reference poses. Every point
// keeps the index of its scan, so its radar pose is known when incidence
// vectors are formed.
#pragma once

#include <cstddef>
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
// One scan's part of a map cloud: its static points in the radar frame (the
// Doppler filter's inliers, or every point), as BuildMapCloud keeps them.
struct StaticScanPoints {
  std::vector<Eigen::Vector3d> positions;  // radar frame
  std::vector<double> rcs;                 // dBsm
  std::size_t points_in = 0;               // the scan's points
  bool has_rcs = false;
  std::size_t MemoryBytes() const {
    return positions.capacity() * sizeof(Eigen::Vector3d) + rcs.capacity() * sizeof(double);
  }
};
StaticScanPoints StaticPointsOf(const RadarScan& scan, const MapCloudOptions& options = {});
// The cloud of scans' static points at their poses T_world_radar (one per
// scan; `scans` point into caller-held parts): BuildMapCloud's cloud of the
// scans the parts came from.
MapCloud MergeStaticPoints(const std::vector<const StaticScanPoints*>& scans, const std::vector<SE3d>& poses,
                           MapCloudStats* stats = nullptr);

inline MapCloud BuildMapCloud(const Sequence& sequence, const MapCloudOptions& options = {},
                              MapCloudStats* stats = nullptr) {
  return BuildMapCloud(sequence.scans, sequence.poses, options, stats);
}

}  // namespace radargauss
