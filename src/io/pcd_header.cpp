// SPDX-License-Identifier: BSD-3-Clause
#include "pcd_header.hpp"

#include <charconv>
#include <cstdint>
#include <sstream>

#include "radargauss/core/error.hpp"

namespace radargauss::internal {

std::vector<std::string> SplitWords(const std::string& line) {
  std::istringstream stream(line);
  std::vector<std::string> words;
  std::string word;
  while (stream >> word) words.push_back(word);
  return words;
}

namespace {

// Bounds on a header (docs/design/formats.md, "Bounds on input"): radar and lidar
// PCDs have tens of fields of a few values; these stop a hostile header from
// turning into large allocations before any data is read.
constexpr std::size_t kMaxPcdFields = 256;
constexpr std::size_t kMaxPcdValuesPerPoint = 1024;  // the sum of COUNT

std::size_t ParseCount(const std::string& path, const std::string& key, const std::string& word) {
  std::size_t value = 0;
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (error != std::errc() || end != word.data() + word.size()) {
    throw FileError(path, key + ": not a non-negative integer: '" + word + "'");
  }
  return value;
}

bool ValidTypeSize(char type, int size) {
  if (type == 'F') return size == 4 || size == 8;
  if (type == 'I' || type == 'U') return size == 1 || size == 2 || size == 4 || size == 8;
  return false;
}

// Each field's type, size, count and offset from the SIZE, TYPE and COUNT
// lines (as long as FIELDS), and the point step.
void ResolveFields(const std::string& path, const std::vector<std::string>& sizes,
                   const std::vector<std::string>& types, const std::vector<std::string>& counts, PcdHeader& header) {
  std::size_t offset = 0;
  std::size_t values = 0;
  for (std::size_t i = 0; i < header.fields.size(); ++i) {
    PcdField& field = header.fields[i];
    if (types[i].size() != 1) throw FileError(path, "unknown TYPE '" + types[i] + "'");
    field.type = types[i][0];
    field.size = static_cast<int>(ParseCount(path, "SIZE", sizes[i]));
    const std::size_t count = counts.empty() ? 1 : ParseCount(path, "COUNT", counts[i]);
    if (count > kMaxPcdValuesPerPoint) throw FileError(path, "COUNT of field '" + field.name + "' is too large");
    field.count = static_cast<int>(count);
    if (!ValidTypeSize(field.type, field.size)) {
      throw FileError(path, "unknown TYPE/SIZE " + types[i] + "/" + sizes[i] + " of field '" + field.name + "'");
    }
    if (field.count < 1) throw FileError(path, "COUNT of field '" + field.name + "' is 0");
    values += static_cast<std::size_t>(field.count);
    if (values > kMaxPcdValuesPerPoint) {
      throw FileError(path, "more than " + std::to_string(kMaxPcdValuesPerPoint) + " values per point");
    }
    field.offset = offset;
    offset += static_cast<std::size_t>(field.size) * field.count;
  }
  header.point_step = offset;
}

}  // namespace

PcdHeader ParsePcdHeader(const std::string& path, const std::string& bytes) {
  PcdHeader header;
  std::vector<std::string> sizes;
  std::vector<std::string> types;
  std::vector<std::string> counts;
  bool have_width = false;
  bool have_height = false;
  bool have_points = false;
  std::size_t position = 0;
  while (header.data.empty()) {
    const std::size_t newline = bytes.find('\n', position);
    if (newline == std::string::npos) throw FileError(path, "PCD header has no DATA line");
    const std::string line = bytes.substr(position, newline - position);
    position = newline + 1;
    const std::vector<std::string> words = SplitWords(line);
    if (words.empty() || words[0][0] == '#') continue;
    const std::string& key = words[0];
    const std::vector<std::string> rest(words.begin() + 1, words.end());
    if (key == "VERSION") {
      if (rest.size() != 1 || (rest[0] != "0.7" && rest[0] != ".7")) {
        throw FileError(path, "unsupported PCD VERSION (0.7 only)");
      }
    } else if (key == "FIELDS") {
      if (!header.fields.empty()) throw FileError(path, "a second FIELDS line");
      if (rest.size() > kMaxPcdFields) {
        throw FileError(path, std::to_string(rest.size()) + " FIELDS, more than " + std::to_string(kMaxPcdFields));
      }
      for (const std::string& name : rest) header.fields.push_back({name, 'F', 4, 1, 0});
    } else if (key == "SIZE") {
      sizes = rest;
    } else if (key == "TYPE") {
      types = rest;
    } else if (key == "COUNT") {
      counts = rest;
    } else if (key == "WIDTH" && rest.size() == 1) {
      header.width = ParseCount(path, key, rest[0]);
      have_width = true;
    } else if (key == "HEIGHT" && rest.size() == 1) {
      header.height = ParseCount(path, key, rest[0]);
      have_height = true;
    } else if (key == "POINTS" && rest.size() == 1) {
      header.points = ParseCount(path, key, rest[0]);
      have_points = true;
    } else if (key == "VIEWPOINT") {
      if (rest.size() != 7) throw FileError(path, "VIEWPOINT needs 7 values");
    } else if (key == "DATA") {
      if (rest.size() != 1 || (rest[0] != "ascii" && rest[0] != "binary" && rest[0] != "binary_compressed")) {
        throw FileError(path, "unknown DATA format (ascii, binary, binary_compressed)");
      }
      header.data = rest[0];
    } else {
      throw FileError(path, "unexpected PCD header line: '" + line + "'");
    }
  }
  header.data_offset = position;

  if (header.fields.empty()) throw FileError(path, "PCD header has no FIELDS");
  const std::size_t n = header.fields.size();
  if (sizes.size() != n || types.size() != n || (!counts.empty() && counts.size() != n)) {
    throw FileError(path, "FIELDS, SIZE, TYPE and COUNT differ in length");
  }
  if (!have_width || !have_height) throw FileError(path, "PCD header lacks WIDTH or HEIGHT");
  if (!have_points) header.points = header.width * header.height;
  if (header.height != 0 && header.width > SIZE_MAX / header.height) throw FileError(path, "WIDTH x HEIGHT overflows");
  if (header.width * header.height != header.points) {
    throw FileError(path, "WIDTH x HEIGHT (" + std::to_string(header.width * header.height) +
                              ") differs from POINTS (" + std::to_string(header.points) + ")");
  }
  ResolveFields(path, sizes, types, counts, header);
  return header;
}

}  // namespace radargauss::internal
