// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/pcd.hpp"

#include <lzf.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"
#include "pcd_header.hpp"

namespace radargauss {

namespace {

// Rejects POINTS that the file cannot hold before anything is allocated for
// them (a corrupt header must not turn into a huge allocation).
void CheckSizeAgainstFile(const std::string& path, const std::string& bytes, const PcdHeader& h) {
  const std::size_t available = bytes.size() - h.data_offset;
  if (h.points != 0 && h.point_step > SIZE_MAX / h.points) {
    throw FileError(path, "POINTS x point size overflows");
  }
  const std::size_t needed = h.points * h.point_step;
  std::size_t bound = 0;
  if (h.data == "ascii") {
    bound = available / 2;  // at least one digit and a separator per value
  } else if (h.data == "binary") {
    bound = available;
  } else {
    // LZF expands at most ~88x (a 3-byte back-reference covers 264 bytes).
    bound = available * 100 + 1024;
  }
  std::size_t values_per_point = 0;
  for (const PcdField& f : h.fields) values_per_point += f.count;
  const std::size_t demand = h.data == "ascii" ? h.points * values_per_point : needed;
  if (demand > bound) {
    throw FileError(path, "truncated: POINTS " + std::to_string(h.points) + " cannot fit in " +
                              std::to_string(available) + " bytes of data");
  }
}

double DecodeValue(const char* p, char type, int size) {
  switch (type) {
    case 'F':
      if (size == 4) {
        float v;
        std::memcpy(&v, p, 4);
        return v;
      }
      {
        double v;
        std::memcpy(&v, p, 8);
        return v;
      }
    case 'I':
      switch (size) {
        case 1: {
          std::int8_t v;
          std::memcpy(&v, p, 1);
          return v;
        }
        case 2: {
          std::int16_t v;
          std::memcpy(&v, p, 2);
          return v;
        }
        case 4: {
          std::int32_t v;
          std::memcpy(&v, p, 4);
          return v;
        }
        default: {
          std::int64_t v;
          std::memcpy(&v, p, 8);
          return static_cast<double>(v);
        }
      }
    default:
      switch (size) {
        case 1: {
          std::uint8_t v;
          std::memcpy(&v, p, 1);
          return v;
        }
        case 2: {
          std::uint16_t v;
          std::memcpy(&v, p, 2);
          return v;
        }
        case 4: {
          std::uint32_t v;
          std::memcpy(&v, p, 4);
          return v;
        }
        default: {
          std::uint64_t v;
          std::memcpy(&v, p, 8);
          return static_cast<double>(v);
        }
      }
  }
}

void DecodeAscii(const std::string& path, const std::string& bytes, PcdCloud& cloud) {
  const PcdHeader& h = cloud.header;
  std::size_t tokens_per_point = 0;
  for (const PcdField& f : h.fields) tokens_per_point += f.count;
  std::istringstream stream(bytes.substr(h.data_offset));
  std::string line;
  std::size_t point = 0;
  while (std::getline(stream, line)) {
    const std::vector<std::string> words = internal::SplitWords(line);
    if (words.empty()) continue;
    if (point >= h.points) throw FileError(path, "more data lines than POINTS");
    if (words.size() != tokens_per_point) {
      throw FileError(path, "data line " + std::to_string(point + 1) + " has " + std::to_string(words.size()) +
                                " values, expected " + std::to_string(tokens_per_point));
    }
    std::size_t token = 0;
    for (std::size_t f = 0; f < h.fields.size(); ++f) {
      const std::string& word = words[token];
      char* end = nullptr;
      const double value = std::strtod(word.c_str(), &end);
      if (end != word.c_str() + word.size()) {
        throw FileError(path, "data line " + std::to_string(point + 1) + ": not a number: '" + word + "'");
      }
      // A float32 field holds the float nearest the decimal, as in the binary formats.
      const bool is_float32 = h.fields[f].type == 'F' && h.fields[f].size == 4;
      cloud.values[f][point] = is_float32 ? double(static_cast<float>(value)) : value;
      token += h.fields[f].count;
    }
    ++point;
  }
  if (point != h.points) {
    throw FileError(path, "truncated: " + std::to_string(point) + " data lines, POINTS is " + std::to_string(h.points));
  }
}

void DecodeBinary(const std::string& path, const std::string& bytes, PcdCloud& cloud) {
  const PcdHeader& h = cloud.header;
  const std::size_t needed = h.points * h.point_step;
  const std::size_t available = bytes.size() - h.data_offset;
  if (available < needed) {
    throw FileError(path, "truncated: " + std::to_string(available) + " bytes of point data, " +
                              std::to_string(needed) + " expected");
  }
  const char* data = bytes.data() + h.data_offset;
  for (std::size_t f = 0; f < h.fields.size(); ++f) {
    const PcdField& field = h.fields[f];
    for (std::size_t i = 0; i < h.points; ++i) {
      cloud.values[f][i] = DecodeValue(data + i * h.point_step + field.offset, field.type, field.size);
    }
  }
}

// binary_compressed: uint32 compressed size, uint32 uncompressed size, LZF
// data; decompressed, each field's values are stored contiguously.
void DecodeBinaryCompressed(const std::string& path, const std::string& bytes, PcdCloud& cloud) {
  const PcdHeader& h = cloud.header;
  const std::size_t available = bytes.size() - h.data_offset;
  if (available < 8) throw FileError(path, "truncated: no compressed-size header");
  std::uint32_t compressed_size = 0;
  std::uint32_t uncompressed_size = 0;
  std::memcpy(&compressed_size, bytes.data() + h.data_offset, 4);
  std::memcpy(&uncompressed_size, bytes.data() + h.data_offset + 4, 4);
  const std::size_t needed = h.points * h.point_step;
  if (uncompressed_size != needed) {
    throw FileError(path, "compressed block declares " + std::to_string(uncompressed_size) +
                              " bytes, POINTS x point size is " + std::to_string(needed));
  }
  if (available - 8 < compressed_size) {
    throw FileError(path, "truncated: compressed block of " + std::to_string(compressed_size) + " bytes, " +
                              std::to_string(available - 8) + " present");
  }
  if (needed == 0) return;
  std::vector<char> raw(needed);
  const unsigned int written = lzf_decompress(bytes.data() + h.data_offset + 8, compressed_size, raw.data(), needed);
  if (written != needed) throw FileError(path, "corrupt LZF data");
  for (std::size_t f = 0; f < h.fields.size(); ++f) {
    const PcdField& field = h.fields[f];
    const std::size_t element = static_cast<std::size_t>(field.size) * field.count;
    const char* column = raw.data() + h.points * field.offset;
    for (std::size_t i = 0; i < h.points; ++i) {
      cloud.values[f][i] = DecodeValue(column + i * element, field.type, field.size);
    }
  }
}

}  // namespace

std::vector<std::string> PcdCloud::FieldNames() const {
  std::vector<std::string> names;
  for (const PcdField& f : header.fields) names.push_back(f.name);
  return names;
}

PcdCloud ReadPcdCloud(const std::string& path) {
  const std::string bytes = ReadFileBytes(path, "PCD file");
  PcdCloud cloud;
  cloud.header = internal::ParsePcdHeader(path, bytes);
  CheckSizeAgainstFile(path, bytes, cloud.header);
  cloud.values.assign(cloud.header.fields.size(), std::vector<double>(cloud.header.points));
  if (cloud.header.data == "ascii") {
    DecodeAscii(path, bytes, cloud);
  } else if (cloud.header.data == "binary") {
    DecodeBinary(path, bytes, cloud);
  } else {
    DecodeBinaryCompressed(path, bytes, cloud);
  }
  return cloud;
}

bool TimestampFromFileName(const std::string& path, double& timestamp) {
  std::string stem = std::filesystem::path(path).stem().string();
  const bool negative = !stem.empty() && stem.front() == '-';  // a clock before its epoch
  if (negative) stem.erase(0, 1);
  const std::size_t dot = stem.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == stem.size()) return false;
  const std::string seconds = stem.substr(0, dot);
  const std::string fraction = stem.substr(dot + 1);
  if (seconds.size() > 12 || fraction.size() > 18) return false;  // not a clock's stamp
  for (const char c : seconds + fraction) {
    if (c < '0' || c > '9') return false;
  }
  // Seconds and fraction separately, so a 10-digit epoch keeps its nanoseconds
  // as well as a double can.
  timestamp = std::stod(seconds) + std::stod(fraction) * std::pow(10.0, -double(fraction.size()));
  if (negative) timestamp = -timestamp;
  return true;
}

RadarScan ReadPcdScan(const std::string& path, const FieldMapping& mapping) {
  const PcdCloud cloud = ReadPcdCloud(path);
  const std::vector<std::string> names = cloud.FieldNames();
  const RadarFieldIndices fields = ResolveRadarFields(names, mapping, path);
  const int ix = fields.x, iy = fields.y, iz = fields.z, irc = fields.rcs, idop = fields.doppler;
  std::vector<int> istd;
  for (const std::string& name : kStdFieldNames) {
    istd.push_back(ResolveField(names, "", {name}, name, path));
  }
  const bool has_std = std::all_of(istd.begin(), istd.end(), [](int i) { return i >= 0; });

  RadarScan scan;
  if (!TimestampFromFileName(path, scan.timestamp)) scan.timestamp = 0.0;
  scan.has_rcs = irc >= 0;
  scan.has_doppler = idop >= 0;
  scan.points.resize(cloud.header.points);
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    RadarPoint& p = scan.points[i];
    p.position = Eigen::Vector3d(cloud.values[ix][i], cloud.values[iy][i], cloud.values[iz][i]);
    if (irc >= 0) p.rcs = cloud.values[irc][i];
    if (idop >= 0) p.doppler = mapping.doppler_sign * cloud.values[idop][i];
    if (has_std) {
      p.std_dev =
          MeasurementStd{static_cast<float>(cloud.values[istd[0]][i]), static_cast<float>(cloud.values[istd[1]][i]),
                         static_cast<float>(cloud.values[istd[2]][i]), static_cast<float>(cloud.values[istd[3]][i])};
    }
  }
  ValidateScan(scan, path);
  return scan;
}

void WritePcdScan(const std::string& path, const RadarScan& scan, PcdFormat format) {
  const bool with_std = !scan.points.empty() && std::all_of(scan.points.begin(), scan.points.end(),
                                                            [](const RadarPoint& p) { return p.std_dev.has_value(); });
  const int n_fields = with_std ? 9 : 5;
  const std::size_t n = scan.points.size();
  // Columns of float32, in field order.
  std::vector<std::vector<float>> columns(n_fields, std::vector<float>(n));
  for (std::size_t i = 0; i < n; ++i) {
    const RadarPoint& p = scan.points[i];
    const float row[9] = {float(p.position.x()),
                          float(p.position.y()),
                          float(p.position.z()),
                          float(p.doppler),
                          float(p.rcs),
                          with_std ? p.std_dev->range : 0.0f,
                          with_std ? p.std_dev->azimuth : 0.0f,
                          with_std ? p.std_dev->elevation : 0.0f,
                          with_std ? p.std_dev->doppler : 0.0f};
    for (int f = 0; f < n_fields; ++f) columns[f][i] = row[f];
  }
  WriteFileAtomically(
      path,
      [&](std::ostream& out) {
        const char* format_name = format == PcdFormat::kAscii    ? "ascii"
                                  : format == PcdFormat::kBinary ? "binary"
                                                                 : "binary_compressed";
        out << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
            << (with_std ? "FIELDS x y z doppler intensity range_std azimuth_std elevation_std "
                           "doppler_std\nSIZE 4 4 4 4 4 4 4 4 4\nTYPE F F F F F F F F F\n"
                           "COUNT 1 1 1 1 1 1 1 1 1\n"
                         : "FIELDS x y z doppler intensity\nSIZE 4 4 4 4 4\nTYPE F F F F F\n"
                           "COUNT 1 1 1 1 1\n")
            << "WIDTH " << n << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << n << "\nDATA " << format_name << "\n";
        if (format == PcdFormat::kAscii) {
          out.precision(9);
          for (std::size_t i = 0; i < n; ++i) {
            for (int f = 0; f < n_fields; ++f) out << (f ? " " : "") << columns[f][i];
            out << "\n";
          }
        } else if (format == PcdFormat::kBinary) {
          std::vector<float> interleaved(n * n_fields);
          for (std::size_t i = 0; i < n; ++i) {
            for (int f = 0; f < n_fields; ++f) interleaved[i * n_fields + f] = columns[f][i];
          }
          out.write(reinterpret_cast<const char*>(interleaved.data()),
                    static_cast<std::streamsize>(interleaved.size() * sizeof(float)));
        } else {
          std::vector<float> by_field;
          for (const auto& column : columns) by_field.insert(by_field.end(), column.begin(), column.end());
          const std::uint32_t raw_size = static_cast<std::uint32_t>(by_field.size() * sizeof(float));
          // LZF may expand incompressible data slightly; give it room.
          std::vector<char> compressed(raw_size + raw_size / 16 + 64);
          std::uint32_t compressed_size = raw_size == 0 ? 0
                                                        : lzf_compress(by_field.data(), raw_size, compressed.data(),
                                                                       static_cast<unsigned int>(compressed.size()));
          if (raw_size != 0 && compressed_size == 0) throw FileError(path, "LZF compression failed");
          out.write(reinterpret_cast<const char*>(&compressed_size), 4);
          out.write(reinterpret_cast<const char*>(&raw_size), 4);
          out.write(compressed.data(), compressed_size);
        }
      },
      /*binary=*/true);
}

}  // namespace radargauss
