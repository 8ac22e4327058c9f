// SPDX-License-Identifier: BSD-3-Clause
#include <algorithm>
#include <cmath>
#include <cstring>

#include "radargauss/core/error.hpp"
#include "radargauss/io/rosbag.hpp"

namespace radargauss {

namespace {

int DatatypeSize(std::uint8_t datatype) {
  switch (datatype) {
    case 1:
    case 2:
      return 1;
    case 3:
    case 4:
      return 2;
    case 5:
    case 6:
    case 7:
      return 4;
    case 8:
      return 8;
    default:
      return 0;
  }
}

double DecodeElement(const std::uint8_t* p, std::uint8_t datatype, bool big_endian) {
  std::uint8_t bytes[8];
  const int size = DatatypeSize(datatype);
  for (int i = 0; i < size; ++i) bytes[i] = big_endian ? p[size - 1 - i] : p[i];
  switch (datatype) {
    case 1: {
      std::int8_t v;
      std::memcpy(&v, bytes, 1);
      return v;
    }
    case 2: {
      std::uint8_t v;
      std::memcpy(&v, bytes, 1);
      return v;
    }
    case 3: {
      std::int16_t v;
      std::memcpy(&v, bytes, 2);
      return v;
    }
    case 4: {
      std::uint16_t v;
      std::memcpy(&v, bytes, 2);
      return v;
    }
    case 5: {
      std::int32_t v;
      std::memcpy(&v, bytes, 4);
      return v;
    }
    case 6: {
      std::uint32_t v;
      std::memcpy(&v, bytes, 4);
      return v;
    }
    case 7: {
      float v;
      std::memcpy(&v, bytes, 4);
      return v;
    }
    default: {
      double v;
      std::memcpy(&v, bytes, 8);
      return v;
    }
  }
}

}  // namespace

RadarScan DecodePointCloud2(const PointCloud2Data& cloud, double timestamp, const FieldMapping& mapping,
                            const std::string& source) {
  std::vector<std::string> names;
  for (const PointCloud2Field& field : cloud.fields) {
    if (DatatypeSize(field.datatype) == 0) {
      throw FileError(source, "field '" + field.name + "' has unknown datatype " + std::to_string(field.datatype));
    }
    if (std::size_t(field.offset) + DatatypeSize(field.datatype) > cloud.point_step) {
      throw FileError(source, "field '" + field.name + "' lies outside point_step");
    }
    names.push_back(field.name);
  }
  if (cloud.width == 0 && cloud.height > 1) {
    throw FileError(source, "height " + std::to_string(cloud.height) + " rows of width 0");
  }
  if (std::size_t(cloud.width) * cloud.point_step > cloud.row_step) {
    throw FileError(source, "row_step is smaller than width x point_step");
  }
  if (std::size_t(cloud.row_step) * cloud.height > cloud.data.size()) {
    throw FileError(source, "data holds " + std::to_string(cloud.data.size()) + " bytes, height x row_step needs " +
                                std::to_string(std::size_t(cloud.row_step) * cloud.height));
  }
  const RadarFieldIndices fields = ResolveRadarFields(names, mapping, source);
  const int ix = fields.x, iy = fields.y, iz = fields.z, irc = fields.rcs, idop = fields.doppler;

  RadarScan scan;
  scan.timestamp = timestamp;
  scan.has_rcs = irc >= 0;
  scan.has_doppler = idop >= 0;
  scan.points.reserve(std::size_t(cloud.width) * cloud.height);
  const auto value = [&](const std::uint8_t* point, int field) {
    const PointCloud2Field& f = cloud.fields[field];
    return DecodeElement(point + f.offset, f.datatype, cloud.is_bigendian);
  };
  for (std::uint32_t row = 0; row < cloud.height; ++row) {
    for (std::uint32_t column = 0; column < cloud.width; ++column) {
      const std::uint8_t* point =
          cloud.data.data() + std::size_t(row) * cloud.row_step + std::size_t(column) * cloud.point_step;
      RadarPoint p;
      p.position = Eigen::Vector3d(value(point, ix), value(point, iy), value(point, iz));
      if (irc >= 0) p.rcs = value(point, irc);
      if (idop >= 0) p.doppler = mapping.doppler_sign * value(point, idop);
      scan.points.push_back(p);
    }
  }
  ValidateScan(scan, source);
  return scan;
}

PointCloud2Data EncodePointCloud2(const RadarScan& scan) {
  PointCloud2Data cloud;
  std::vector<std::string> names = {"x", "y", "z"};
  if (scan.has_doppler) names.push_back("doppler");
  if (scan.has_rcs) names.push_back("rcs");
  for (std::size_t i = 0; i < names.size(); ++i) cloud.fields.push_back({names[i], std::uint32_t(8 * i), 8, 1});
  cloud.point_step = std::uint32_t(8 * names.size());
  cloud.width = std::uint32_t(scan.points.size());
  cloud.row_step = cloud.width * cloud.point_step;
  cloud.data.resize(std::size_t(cloud.row_step));
  std::uint8_t* out = cloud.data.data();
  for (const RadarPoint& p : scan.points) {
    double values[5] = {p.position.x(), p.position.y(), p.position.z(), 0.0, 0.0};
    int n = 3;
    if (scan.has_doppler) values[n++] = p.doppler;
    if (scan.has_rcs) values[n++] = p.rcs;
    for (int i = 0; i < n; ++i) {  // little-endian on every host
      std::uint64_t bits;
      std::memcpy(&bits, &values[i], 8);
      for (int b = 0; b < 8; ++b) *out++ = std::uint8_t(bits >> (8 * b));
    }
  }
  return cloud;
}

}  // namespace radargauss
