// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/core/voxel_grid.hpp"

#include <algorithm>
#include <utility>

#include "radargauss/core/linear_probing_table.hpp"

namespace radargauss {

namespace {

int BitWidth(std::uint64_t value) {
  int bits = 0;
  for (; value != 0; value >>= 1) ++bits;
  return bits;
}

// The indices of `order` (sorted by key) cut into runs of one key each.
std::vector<std::vector<std::uint32_t>> SplitRuns(const std::vector<std::uint32_t>& order,
                                                  const std::vector<VoxelKey>& keys) {
  std::vector<std::vector<std::uint32_t>> groups;
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (k == 0 || !(keys[order[k]] == keys[order[k - 1]])) groups.emplace_back();
    groups.back().push_back(order[k]);
  }
  return groups;
}

}  // namespace

std::vector<std::vector<std::uint32_t>> GroupByVoxel(const std::vector<Eigen::Vector3d>& points, double voxel) {
  const std::size_t n = points.size();
  if (n == 0) return {};
  std::vector<VoxelKey> keys(n);
  VoxelKey low = VoxelOf(points[0], voxel), high = low;
  for (std::size_t i = 0; i < n; ++i) {
    keys[i] = VoxelOf(points[i], voxel);
    low = {std::min(low.x, keys[i].x), std::min(low.y, keys[i].y), std::min(low.z, keys[i].z)};
    high = {std::max(high.x, keys[i].x), std::max(high.y, keys[i].y), std::max(high.z, keys[i].z)};
  }
  // When the keys' spans and the index fit in 63 bits, one integer per point
  // (x, y, z offsets, then the index) sorts in the keys' order, ties by index.
  const int bits_z = BitWidth(std::uint64_t(high.z) - std::uint64_t(low.z));
  const int bits_y = BitWidth(std::uint64_t(high.y) - std::uint64_t(low.y));
  const int bits_x = BitWidth(std::uint64_t(high.x) - std::uint64_t(low.x));
  const int bits_i = BitWidth(n - 1);
  std::vector<std::uint32_t> order(n);
  if (bits_x + bits_y + bits_z + bits_i <= 63) {
    std::vector<std::uint64_t> codes(n);
    for (std::size_t i = 0; i < n; ++i) {
      codes[i] = ((std::uint64_t(keys[i].x) - std::uint64_t(low.x)) << (bits_y + bits_z + bits_i)) |
                 ((std::uint64_t(keys[i].y) - std::uint64_t(low.y)) << (bits_z + bits_i)) |
                 ((std::uint64_t(keys[i].z) - std::uint64_t(low.z)) << bits_i) | std::uint64_t(i);
    }
    std::sort(codes.begin(), codes.end());
    const std::uint64_t index_mask = (std::uint64_t(1) << bits_i) - 1;
    for (std::size_t k = 0; k < n; ++k) order[k] = std::uint32_t(codes[k] & index_mask);
  } else {
    for (std::size_t i = 0; i < n; ++i) order[i] = std::uint32_t(i);
    std::sort(order.begin(), order.end(),
              [&](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b] || (keys[a] == keys[b] && a < b); });
  }
  return SplitRuns(order, keys);
}

std::vector<Eigen::Vector3d> VoxelDownsample(const std::vector<Eigen::Vector3d>& points, double voxel,
                                             VoxelOrder order) {
  // Sums per occupied voxel, found through a LinearProbingTable, in the
  // order of their first points: a scan's coarse levels downsample it on
  // every match, so this sorts neither the points nor, unless asked, the voxels.
  struct Voxel {
    VoxelKey key;
    Eigen::Vector3d sum;
    std::uint32_t count;
  };
  struct Slot {
    VoxelKey key;
    std::int32_t voxel;  // index into voxels; -1: free
  };
  std::vector<Voxel> voxels;
  LinearProbingTable<Slot> table;
  table.Reset(points.size(), Slot{{0, 0, 0}, -1});
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) continue;
    const VoxelKey key = VoxelOf(p, voxel);
    Slot& slot = table[table.Probe(std::uint64_t(PackVoxelKey(key)),
                                   [&key](const Slot& s) { return s.voxel < 0 || s.key == key; })];
    if (slot.voxel < 0) {
      slot = {key, std::int32_t(voxels.size())};
      voxels.push_back({key, p, 1});
    } else {
      Voxel& v = voxels[slot.voxel];
      v.sum += p;
      ++v.count;
    }
  }
  if (order == VoxelOrder::kByKey) {
    std::sort(voxels.begin(), voxels.end(), [](const Voxel& a, const Voxel& b) { return a.key < b.key; });
  }
  std::vector<Eigen::Vector3d> centroids;
  centroids.reserve(voxels.size());
  for (const Voxel& v : voxels) centroids.push_back(v.sum / double(v.count));
  return centroids;
}

}  // namespace radargauss
