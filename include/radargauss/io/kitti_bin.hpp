// SPDX-License-Identifier: BSD-3-Clause
// KITTI-style .bin radar scans: consecutive records of float32 fields in a
// declared order (View-of-Delft: "x y z rcs v_r v_r_comp time").
#pragma once

#include <string>
#include <vector>

#include "radargauss/io/field_mapping.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

inline const char* kViewOfDelftLayout = "x y z rcs v_r v_r_comp time";

// Field names of a layout: a space- or comma-separated list, or the preset
// "vod". Throws std::invalid_argument if it lacks x, y or z or repeats a name.
std::vector<std::string> ParseBinLayout(const std::string& layout);

// Throws DataError naming the file when its size is not a whole number of
// records, or a point is not finite. The timestamp comes from the file name
// ("<secs>.<fraction>.bin") when it has that form, else 0.
RadarScan ReadKittiBin(const std::string& path, const std::vector<std::string>& layout,
                       const FieldMapping& mapping = {});

}  // namespace radargauss
