// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/voxel_grid.hpp"

#include <utility>

#include "radargauss/linear_probing_table.hpp"

namespace radargauss {

std::vector<std::vector<std::uint32_t>> GroupByVoxel(const std::vector<Eigen::Vector3d>& points, double voxel) {
  std::vector<std::pair<VoxelKey, std::uint32_t>> keyed(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) keyed[i] = {VoxelOf(points[i], voxel), std::uint32_t(i)};
  std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) {
    return a.first < b.first || (a.first == b.first && a.second < b.second);
  });
  std::vector<std::vector<std::uint32_t>> groups;
  for (std::size_t k = 0; k < keyed.size(); ++k) {
    if (k == 0 || !(keyed[k].first == keyed[k - 1].first)) groups.emplace_back();
    groups.back().push_back(keyed[k].second);
  }
  return groups;
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
