// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/map/pipeline.hpp"

#include <utility>

#include "radargauss/core/error.hpp"

namespace radargauss {

const OptionTable<MapOptions>& MapOptionTable() {
  using O = MapOptions;
  static const OptionTable<O> table = [] {
    OptionTable<O> t = {RADARGAUSS_OPTION(O, "doppler_filter", cloud.doppler_filter)
                            .Help("keep only the scans' ego-velocity inliers (false: dynamic points too)")};
    AppendNested(
        t, EgoVelocityOptionTable(), +[](O & o) -> auto& { return o.cloud.ego_velocity; }, "cloud.ego_velocity",
        "cloud_");
    AppendNested(
        t, GaussianMapOptionTable(), +[](O & o) -> auto& { return o.gaussians; }, "gaussians");
    AppendNested(
        t, RcsFitOptionTable(), +[](O & o) -> auto& { return o.rcs; }, "rcs");
    return t;
  }();
  return table;
}

void ValidateOptions(const MapOptions& o) { CheckOptions(MapOptionTable(), o); }

MapGeometry BuildMapGeometry(const std::vector<RadarScan>& scans, const std::vector<SE3d>& poses,
                             const MapOptions& options, const ProgressCallback& progress) {
  MapCloudStats stats;
  MapGeometry geometry = BuildMapGeometry(BuildMapCloud(scans, poses, options.cloud, &stats), options, progress);
  geometry.cloud_stats = stats;
  return geometry;
}

MapGeometry BuildMapGeometry(MapCloud cloud, const MapOptions& options, const ProgressCallback& progress) {
  if (cloud.points.empty()) throw DataError("no static points to build a map from");
  MapGeometry geometry;
  geometry.cloud = std::move(cloud);
  geometry.map.gaussians = BuildGaussians(geometry.cloud.points, options.gaussians, progress, &geometry.association);
  return geometry;
}

GaussianMap FitRcs(const MapGeometry& geometry, const RcsFitOptions& options, RcsFitStats* stats) {
  GaussianMap map = geometry.map;
  const RcsFitStats fitted = FitRcsModels(map, geometry.cloud, geometry.association, options);
  if (stats) *stats = fitted;
  return map;
}

}  // namespace radargauss
