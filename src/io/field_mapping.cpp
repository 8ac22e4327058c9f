// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/field_mapping.hpp"

#include <algorithm>

#include "radargauss/core/error.hpp"

namespace radargauss {

int ResolveField(const std::vector<std::string>& available, const std::string& requested,
                 const std::vector<std::string>& defaults, const std::string& role, const std::string& source) {
  const auto index_of = [&](const std::string& name) {
    const auto it = std::find(available.begin(), available.end(), name);
    return it == available.end() ? -1 : static_cast<int>(it - available.begin());
  };
  if (requested == "none") return -1;
  if (!requested.empty()) {
    const int index = index_of(requested);
    if (index < 0) throw FileError(source, role + " field '" + requested + "' not present");
    return index;
  }
  for (const std::string& name : defaults) {
    const int index = index_of(name);
    if (index >= 0) return index;
  }
  return -1;
}

RadarFieldIndices ResolveRadarFields(const std::vector<std::string>& available, const FieldMapping& mapping,
                                     const std::string& source) {
  const auto required = [&](const char* name) {
    const int index = ResolveField(available, "", {name}, name, source);
    if (index < 0) throw FileError(source, std::string("no '") + name + "' field");
    return index;
  };
  RadarFieldIndices fields;
  fields.x = required("x");
  fields.y = required("y");
  fields.z = required("z");
  fields.rcs = ResolveField(available, mapping.rcs_field, kRcsFieldNames, "RCS", source);
  fields.doppler = ResolveField(available, mapping.doppler_field, kDopplerFieldNames, "Doppler", source);
  return fields;
}

}  // namespace radargauss
