// SPDX-License-Identifier: BSD-3-Clause
// Voxel grids over points: the integer voxel of a point and its packed key
// (the spatial index's cells, docs/design/map.md, "The spatial index"), points
// grouped by voxel, and voxel centroids (downsampling).
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace radargauss {

// The integer voxel of a point in a grid of side `voxel` (floor(p / voxel)),
// ordered so that it can key sorted containers.
struct VoxelKey {
  std::int64_t x, y, z;
  bool operator<(const VoxelKey& o) const { return x != o.x ? x < o.x : (y != o.y ? y < o.y : z < o.z); }
  bool operator==(const VoxelKey& o) const { return x == o.x && y == o.y && z == o.z; }
};

// floor(x) as an integer, inline (std::floor is a library call without
// SSE4.1); saturated at +-2^62, where the conversion would be undefined
// (cells alias there, which costs candidates, not answers).
inline std::int64_t FloorToInt(double x) {
  constexpr double kLimit = 4.611686018427387904e18;  // 2^62
  x = std::min(std::max(x, -kLimit), kLimit);
  const auto truncated = static_cast<std::int64_t>(x);
  return truncated - (static_cast<double>(truncated) > x);
}

inline VoxelKey VoxelOf(const Eigen::Vector3d& p, double voxel) {
  // One division, then products: monotone in p, so a point inside a box is
  // in one of the voxels of the box's corners.
  const double inverse = 1.0 / voxel;
  return {FloorToInt(p.x() * inverse), FloorToInt(p.y() * inverse), FloorToInt(p.z() * inverse)};
}

// The voxel packed into one non-negative integer, 21 bits per axis (wrapping:
// a hash, and the spatial index's cell key).
inline std::int64_t PackVoxelKey(std::int64_t x, std::int64_t y, std::int64_t z) {
  constexpr std::int64_t kKeyBits = 21;
  constexpr std::int64_t kKeyOffset = std::int64_t(1) << (kKeyBits - 1);
  constexpr std::int64_t kKeyMask = (std::int64_t(1) << kKeyBits) - 1;
  return ((x + kKeyOffset) & kKeyMask) | (((y + kKeyOffset) & kKeyMask) << kKeyBits) |
         (((z + kKeyOffset) & kKeyMask) << (2 * kKeyBits));
}
inline std::int64_t PackVoxelKey(const VoxelKey& key) { return PackVoxelKey(key.x, key.y, key.z); }

// The indices of `points` grouped by voxel of edge `voxel`: groups in voxel
// key order, indices ascending within each.
std::vector<std::vector<std::uint32_t>> GroupByVoxel(const std::vector<Eigen::Vector3d>& points, double voxel);

// Centroids of the occupied voxels of edge `voxel` (non-finite points
// skipped), ordered by voxel key or, cheaper, by each voxel's first point.
enum class VoxelOrder { kByKey, kFirstPoint };
std::vector<Eigen::Vector3d> VoxelDownsample(const std::vector<Eigen::Vector3d>& points, double voxel,
                                             VoxelOrder order = VoxelOrder::kByKey);

}  // namespace radargauss
