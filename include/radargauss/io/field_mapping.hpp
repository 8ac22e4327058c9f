// SPDX-License-Identifier: BSD-3-Clause
// Which input field carries RCS and which carries Doppler, and the Doppler
// sign, shared by every loader (PCD, KITTI-style .bin, ROS1 PointCloud2).
#pragma once

#include <string>
#include <vector>

namespace radargauss {

struct FieldMapping {
  // Empty: the first present of kRcsFieldNames / kDopplerFieldNames; a named
  // field that is absent is an error. "none" disables the field.
  std::string rcs_field;
  std::string doppler_field;
  // The file's Doppler times this gives radargauss's convention (positive
  // receding, conventions.hpp). -1 for sensors that report approach as positive.
  double doppler_sign = 1.0;
};

inline const std::vector<std::string> kRcsFieldNames = {"rcs", "RCS", "intensity", "power"};
inline const std::vector<std::string> kDopplerFieldNames = {"doppler", "velocity", "v_r", "radial_velocity", "vel"};
// The per-point standard deviations (Snail-Radar / ARS548); used when all four exist.
inline const std::vector<std::string> kStdFieldNames = {"range_std", "azimuth_std", "elevation_std", "doppler_std"};

// Resolves `requested` (see FieldMapping) against the available names: the
// index of the field, or -1 for none. Throws DataError naming `source` when a
// requested field is absent.
int ResolveField(const std::vector<std::string>& available, const std::string& requested,
                 const std::vector<std::string>& defaults, const std::string& role, const std::string& source);

// The radar fields of a record: x y z (required) and RCS / Doppler by the
// mapping (-1 when absent or "none"). Throws DataError naming `source`.
struct RadarFieldIndices {
  int x = -1, y = -1, z = -1, rcs = -1, doppler = -1;
};
RadarFieldIndices ResolveRadarFields(const std::vector<std::string>& available, const FieldMapping& mapping,
                                     const std::string& source);

}  // namespace radargauss
