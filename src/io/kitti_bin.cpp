// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/kitti_bin.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <stdexcept>

#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"
#include "radargauss/io/pcd.hpp"

namespace radargauss {

std::vector<std::string> ParseBinLayout(const std::string& layout) {
  std::string text = layout == "vod" ? kViewOfDelftLayout : layout;
  std::replace(text.begin(), text.end(), ',', ' ');
  std::istringstream stream(text);
  std::vector<std::string> fields;
  std::set<std::string> seen;
  std::string name;
  while (stream >> name) {
    if (!seen.insert(name).second) throw std::invalid_argument("bin layout repeats '" + name + "'");
    fields.push_back(name);
  }
  for (const char* axis : {"x", "y", "z"}) {
    if (!seen.count(axis)) {
      throw std::invalid_argument(std::string("bin layout '") + layout + "' lacks field " + axis);
    }
  }
  return fields;
}

RadarScan ReadKittiBin(const std::string& path, const std::vector<std::string>& layout, const FieldMapping& mapping) {
  if (layout.empty()) throw std::invalid_argument("ReadKittiBin: the layout has no fields");
  const std::string bytes = ReadFileBytes(path, "scan file");
  const std::size_t record = layout.size() * sizeof(float);
  if (bytes.size() % record != 0) {
    throw FileError(path, "truncated: " + std::to_string(bytes.size()) + " bytes is not a whole number of " +
                              std::to_string(record) + "-byte records (" + std::to_string(layout.size()) +
                              " float32 fields)");
  }
  const RadarFieldIndices fields = ResolveRadarFields(layout, mapping, path);
  const int ix = fields.x, iy = fields.y, iz = fields.z, irc = fields.rcs, idop = fields.doppler;

  RadarScan scan;
  if (!TimestampFromFileName(path, scan.timestamp)) scan.timestamp = 0.0;
  scan.has_rcs = irc >= 0;
  scan.has_doppler = idop >= 0;
  const std::size_t n = bytes.size() / record;
  scan.points.resize(n);
  std::vector<float> values(layout.size());
  for (std::size_t i = 0; i < n; ++i) {
    std::memcpy(values.data(), bytes.data() + i * record, record);
    RadarPoint& p = scan.points[i];
    p.position = Eigen::Vector3d(values[ix], values[iy], values[iz]);
    if (irc >= 0) p.rcs = values[irc];
    if (idop >= 0) p.doppler = mapping.doppler_sign * values[idop];
  }
  ValidateScan(scan, path);
  return scan;
}

}  // namespace radargauss
