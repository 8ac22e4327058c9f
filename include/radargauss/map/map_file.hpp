// SPDX-License-Identifier: BSD-3-Clause
// Gaussian-RCS map files.
//
// .rgm, version 3, little-endian:
//   "RGAUSMAP" | u32 version | u8 incidence model | 3 zero bytes | u64 count |
//   count x { f64 mean[3] | f64 covariance[6] (xx xy xz yy yz zz) |
//             u32 point_count | i32 sh_degree (-1: no model) | f64 rcs_median |
//             f64 rcs_scale | f64 fit_rmse | u32 inliers | f64 coefficients[16] |
//             f64 spread_db | f64 explained | f64 mean_offset_db } |
//   u64 places | places x { f64 q[4] (x y z w) | f64 t[3] | u64 n |
//                           n x { f32 x y z rcs } } |
//   u32 CRC32 (zlib) of everything before it.
// Versions 1 (no places section) and 2 (no fit statistics: spread_db from
// fit_rmse, explained 1, mean_offset_db 0) are still read.
// Written to a temporary file and renamed: never a half-written map.
//
// PLY export in the 3D Gaussian Splatting layout (binary little-endian
// float32: x y z nx ny nz f_dc_0..2 f_rest_0..44 opacity scale_0..2 rot_0..3):
// scale = log of the principal stds, rot = the principal axes as a quaternion
// (w first), and the RCS model mapped to colour: every channel's SH
// coefficients are 0.5 c, so a splat viewer shows 0.5 + 0.5 y, the
// normalised RCS, as a grey level that changes with the viewing direction
// (evaluated with the viewer's world-frame direction; ours is radar-frame).
// Gaussians without a model are flat grey.
#pragma once

#include <cstdint>
#include <string>

#include "radargauss/map/gaussian_map.hpp"

namespace radargauss {

inline constexpr std::uint32_t kMapFileVersion = 3;

// What ReadMap accepts of a Gaussian (docs/design/formats.md, "Bounds on input"):
// every mean coordinate within kMaxMapCoordinate of the origin (UTM
// northings fit), principal stds within [kMinMapStd, kMaxMapStd] (a radar
// map's Gaussians are centimetres to metres; a kilometre one would list
// itself in millions of index cells), and finite RCS numbers.
inline constexpr double kMaxMapCoordinate = 1e7;  // m
inline constexpr double kMinMapStd = 1e-4;        // m
inline constexpr double kMaxMapStd = 100.0;       // m
// What it accepts of a place: its position within kMaxMapCoordinate like a
// Gaussian's mean, and its submap's points within kMaxPlaceRadius of it (a
// submap is a few hundred metres of driving seen by a radar, not a country).
inline constexpr double kMaxPlaceRadius = 1e5;  // m

void WriteMap(const std::string& path, const GaussianMap& map);
// Throws DataError naming the file for a missing or truncated file, a wrong
// magic or version, a CRC mismatch, a Gaussian outside the bounds above, or
// a place with a non-finite or non-unit pose, a position beyond
// kMaxMapCoordinate, or a point that is not finite or lies beyond
// kMaxPlaceRadius of its place.
GaussianMap ReadMap(const std::string& path);

void ExportPly(const std::string& path, const GaussianMap& map);

}  // namespace radargauss
