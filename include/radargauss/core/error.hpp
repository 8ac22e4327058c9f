// SPDX-License-Identifier: BSD-3-Clause
// Errors at the library's edges (files, flags, user data) are exceptions of
// these types, with a one-line message that names the source and the fault.
// Programmer errors inside the library are assertions instead.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

namespace radargauss {

// Bad input data: a malformed, truncated or inconsistent file or scan.
class DataError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "<path>: <what>" and "<path>:<line>: <what>", the message forms of DataError.
inline DataError FileError(const std::string& path, const std::string& what) { return DataError(path + ": " + what); }
inline DataError FileError(const std::string& path, std::size_t line, const std::string& what) {
  return DataError(path + ":" + std::to_string(line) + ": " + what);
}

// `text` with every byte outside printable ASCII written as \xNN: names and
// keys echoed in messages cannot retitle or clear the terminal.
inline std::string Printable(const std::string& text) {
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte < 0x7f) {
      out += c;
    } else {
      out += {'\\', 'x', kHex[byte >> 4], kHex[byte & 15]};
    }
  }
  return out;
}

}  // namespace radargauss
