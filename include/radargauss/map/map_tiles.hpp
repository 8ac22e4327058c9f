// SPDX-License-Identifier: BSD-3-Clause
// A map of the place in square tiles (docs/design/slam.md, "Map tiles"): a folder
// with one map file (.rgm, map_file.hpp) per tile of `tile_size` metres in
// x and y, holding the Gaussians whose mean and the places whose pose lie in
// it, and `tiles.json`, the index:
//
//   {"format": "radargauss map tiles", "version": 1, "tile_size": 100.0,
//    "incidence": "offset", "gaussians": N, "places": P,
//    "tiles": [{"x": i, "y": j, "file": "tile_i_j.rgm", "gaussians": n,
//               "places": [indices in the map]}, ...],
//    "order": [[tile, count], ...]}   (the tiles of the Gaussians in the map's order, run-length)
//
// Read whole, the folder gives the map back as it was (same order); read by
// neighbourhood, the Gaussians and places of the tiles that reach within a
// radius of a point, in the map's order, so that a map larger than memory
// can be used a piece at a time.
#pragma once

#include <string>

#include <Eigen/Core>

#include "radargauss/map/gaussian_map.hpp"

namespace radargauss {

inline constexpr int kMapTilesVersion = 1;

// Writes `map` into the folder `dir` (created; every file whole, the index
// last). Throws std::invalid_argument for a tile_size not above 0 and
// DataError for a folder that holds files already or cannot be written.
void WriteMapTiles(const std::string& dir, const GaussianMap& map, double tile_size = 100.0);

// Whether `path` is a folder of map tiles (has tiles.json).
bool IsMapTiles(const std::string& path);

// The whole map. Throws DataError naming the file for a missing or malformed
// index (unknown format or version, counts that do not add up, a place listed
// twice or not at all) and for a tile that is missing, unreadable
// (ReadMap's errors) or holds other counts than its index says.
GaussianMap ReadMapTiles(const std::string& dir);
// The tiles within `radius` metres of `center` (x, y), in the map's order.
GaussianMap ReadMapTiles(const std::string& dir, const Eigen::Vector2d& center, double radius);

// A map file (ReadMap), or a folder of map tiles read whole.
GaussianMap ReadMapOrTiles(const std::string& path);

}  // namespace radargauss
