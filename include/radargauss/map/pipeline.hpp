// SPDX-License-Identifier: BSD-3-Clause
// The map pipeline of docs/design/map.md, "Building the map": static points
// (Doppler filter) merged with the reference poses, Gaussians, RCS models.
// BuildMap (radargauss.hpp) runs it in one call; the two stages are public
// so that several RCS fits (incidence models, degrees) share one geometry.
#pragma once

#include <vector>

#include "radargauss/io/sequence.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/map/rcs_model.hpp"

namespace radargauss {

struct MapOptions {
  MapCloudOptions cloud;         // Doppler filter
  GaussianMapOptions gaussians;  // builder, density, EM
  RcsFitOptions rcs;             // incidence model, SH degree
};
// Its options (options.hpp): the Doppler filter's (cloud_*), the Gaussians'
// and the RCS models'; ValidateOptions throws std::invalid_argument naming the bad one.
const OptionTable<MapOptions>& MapOptionTable();
void ValidateOptions(const MapOptions& options);

// The geometric part of a map: the static cloud, its Gaussians (no RCS
// models yet) and the Gaussian each cloud point belongs to (-1: none).
struct MapGeometry {
  MapCloud cloud;
  MapCloudStats cloud_stats;
  GaussianMap map;
  std::vector<int> association;
};

// From scans and their poses T_world_radar (one per scan). Throws DataError
// when the counts differ or no point is static.
MapGeometry BuildMapGeometry(const std::vector<RadarScan>& scans, const std::vector<SE3d>& poses,
                             const MapOptions& options = {}, const ProgressCallback& progress = {});
// The same from a static cloud already merged (options.cloud unused).
MapGeometry BuildMapGeometry(MapCloud cloud, const MapOptions& options = {}, const ProgressCallback& progress = {});

// The geometry's map with the RCS model of every Gaussian fitted.
GaussianMap FitRcs(const MapGeometry& geometry, const RcsFitOptions& options = {}, RcsFitStats* stats = nullptr);

}  // namespace radargauss
