// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/map/map_cloud.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>

#include "radargauss/core/error.hpp"

namespace radargauss {

StaticScanPoints StaticPointsOf(const RadarScan& scan, const MapCloudOptions& options) {
  StaticScanPoints part;
  part.points_in = scan.points.size();
  part.has_rcs = scan.has_rcs;
  std::vector<bool> keep;
  if (options.doppler_filter && scan.has_doppler) {
    keep = EstimateEgoVelocity(scan, options.ego_velocity).inlier;
  } else {
    keep.assign(scan.points.size(), true);
  }
  const std::size_t kept = std::size_t(std::count(keep.begin(), keep.end(), true));
  part.positions.reserve(kept);
  part.rcs.reserve(kept);
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    if (!keep[i]) continue;
    part.positions.push_back(scan.points[i].position);
    part.rcs.push_back(scan.points[i].rcs);
  }
  return part;
}

MapCloud MergeStaticPoints(const std::vector<const StaticScanPoints*>& scans, const std::vector<SE3d>& poses,
                           MapCloudStats* stats) {
  if (poses.size() != scans.size()) {
    throw DataError("building a map needs one pose per scan: " + std::to_string(scans.size()) + " scans, " +
                    std::to_string(poses.size()) + " poses");
  }
  const std::size_t n = scans.size();
  MapCloud cloud;
  cloud.poses = poses;
  cloud.has_rcs = n > 0;
  MapCloudStats local;
  std::size_t total = 0;
  for (const StaticScanPoints* part : scans) total += part->positions.size();
  cloud.points.reserve(total);
  cloud.rcs.reserve(total);
  cloud.scan.reserve(total);
  for (std::size_t k = 0; k < n; ++k) {
    const StaticScanPoints& part = *scans[k];
    cloud.has_rcs = cloud.has_rcs && part.has_rcs;
    local.points_in += part.points_in;
    for (std::size_t i = 0; i < part.positions.size(); ++i) {
      cloud.points.push_back(poses[k] * part.positions[i]);
      cloud.rcs.push_back(part.rcs[i]);
      cloud.scan.push_back(static_cast<std::uint32_t>(k));
    }
    local.scans_without_ego_velocity += (part.positions.empty() && part.points_in > 0);
    local.points_static += part.positions.size();
  }
  local.scans = n;
  if (stats) *stats = local;
  return cloud;
}

MapCloud BuildMapCloud(const std::vector<RadarScan>& scans, const std::vector<SE3d>& poses,
                       const MapCloudOptions& options, MapCloudStats* stats) {
  if (poses.size() != scans.size()) {
    throw DataError("building a map needs one pose per scan: " + std::to_string(scans.size()) + " scans, " +
                    std::to_string(poses.size()) + " poses");
  }
  // Ego velocity per scan in parallel; results are per scan, so the merge
  // is the same for any thread count.
  std::vector<StaticScanPoints> parts(scans.size());
  tbb::parallel_for(std::size_t(0), scans.size(), [&](std::size_t k) { parts[k] = StaticPointsOf(scans[k], options); });
  std::vector<const StaticScanPoints*> pointers;
  pointers.reserve(parts.size());
  for (const StaticScanPoints& part : parts) pointers.push_back(&part);
  return MergeStaticPoints(pointers, poses, stats);
}

}  // namespace radargauss
