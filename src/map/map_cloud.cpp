// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/map/map_cloud.hpp"

#include <tbb/parallel_for.h>

#include "radargauss/core/error.hpp"

namespace radargauss {

MapCloud BuildMapCloud(const std::vector<RadarScan>& scans, const std::vector<SE3d>& poses,
                       const MapCloudOptions& options, MapCloudStats* stats) {
  if (poses.size() != scans.size()) {
    throw DataError("building a map needs one pose per scan: " + std::to_string(scans.size()) + " scans, " +
                    std::to_string(poses.size()) + " poses");
  }
  const std::size_t n = scans.size();
  // Ego velocity per scan in parallel; results are per scan, so the merge
  // below is the same for any thread count.
  std::vector<std::vector<bool>> keep(n);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t k) {
    const RadarScan& scan = scans[k];
    if (options.doppler_filter && scan.has_doppler) {
      keep[k] = EstimateEgoVelocity(scan, options.ego_velocity).inlier;
    } else {
      keep[k].assign(scan.points.size(), true);
    }
  });
  MapCloud cloud;
  cloud.poses = poses;
  cloud.has_rcs = n > 0;
  MapCloudStats local;
  for (std::size_t k = 0; k < n; ++k) {
    const RadarScan& scan = scans[k];
    cloud.has_rcs = cloud.has_rcs && scan.has_rcs;
    local.points_in += scan.points.size();
    std::size_t kept = 0;
    for (std::size_t i = 0; i < scan.points.size(); ++i) {
      if (!keep[k][i]) continue;
      cloud.points.push_back(poses[k] * scan.points[i].position);
      cloud.rcs.push_back(scan.points[i].rcs);
      cloud.scan.push_back(static_cast<std::uint32_t>(k));
      ++kept;
    }
    local.scans_without_ego_velocity += (kept == 0 && !scan.points.empty());
    local.points_static += kept;
  }
  local.scans = n;
  if (stats) *stats = local;
  return cloud;
}

}  // namespace radargauss
