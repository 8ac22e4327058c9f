// SPDX-License-Identifier: BSD-3-Clause
// PCD v0.7 point clouds (ascii, binary, binary_compressed with LZF), read
// without PCL. Any field set and any PCL numeric type; radar fields are picked
// by a FieldMapping. Every fault (header, sizes, counts against the file
// length, decompression, NaN/inf) is a DataError naming the file.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "radargauss/io/field_mapping.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

struct PcdField {
  std::string name;
  char type = 'F';         // F (float), I (signed), U (unsigned)
  int size = 4;            // bytes per element: F 4/8, I/U 1/2/4/8
  int count = 1;           // elements per point; only the first is read
  std::size_t offset = 0;  // byte offset within a point (binary layouts)
};

struct PcdHeader {
  std::vector<PcdField> fields;
  std::size_t width = 0;
  std::size_t height = 0;
  std::size_t points = 0;
  std::string data;             // ascii, binary or binary_compressed
  std::size_t point_step = 0;   // bytes per point
  std::size_t data_offset = 0;  // bytes from the file start to the data
};

// A PCD file as columns: values[f][i] is the first element of field f of point i.
struct PcdCloud {
  PcdHeader header;
  std::vector<std::vector<double>> values;
  std::vector<std::string> FieldNames() const;
};

PcdCloud ReadPcdCloud(const std::string& path);

// Reads a radar scan: x y z required, RCS / Doppler / stds through `mapping`.
// The timestamp is taken from the file name "<secs>.<fraction>.pcd" when it
// has that form, else 0.
RadarScan ReadPcdScan(const std::string& path, const FieldMapping& mapping = {});

enum class PcdFormat { kAscii, kBinary, kBinaryCompressed };

// Writes float32 fields x y z doppler intensity (intensity = RCS in dBsm, the
// Snail-Radar layout) plus range_std azimuth_std elevation_std doppler_std
// when every point has them; written atomically.
void WritePcdScan(const std::string& path, const RadarScan& scan, PcdFormat format = PcdFormat::kBinary);

// The scan time encoded in a file name "<secs>.<fraction>.pcd" (a leading
// '-' for stamps before the clock's epoch; at most 12 + 18 digits), or false.
bool TimestampFromFileName(const std::string& path, double& timestamp);

}  // namespace radargauss
