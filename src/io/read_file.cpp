// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/read_file.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>

#include "radargauss/error.hpp"

namespace radargauss {

std::string ReadFileBytes(const std::string& path, const std::string& what) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) throw FileError(path, "is a directory, not a " + what);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError(path, "cannot open " + what);
  try {
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw FileError(path, "read error");
    return bytes;
  } catch (const std::ios_base::failure&) {
    throw FileError(path, "read error");
  }
}

}  // namespace radargauss
