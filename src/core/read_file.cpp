// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/core/read_file.hpp"

#include <sys/stat.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <set>
#include <utility>

#include "radargauss/core/error.hpp"

namespace radargauss {

namespace {

namespace fs = std::filesystem;

const char* TypeName(fs::file_type type) {
  switch (type) {
    case fs::file_type::directory:
      return "a directory";
    case fs::file_type::character:
      return "a character device";
    case fs::file_type::block:
      return "a block device";
    case fs::file_type::fifo:
      return "a FIFO";
    case fs::file_type::socket:
      return "a socket";
    default:
      return "not a regular file";
  }
}

// The files read since ProtectInputs(), by device and inode.
std::atomic<bool> protecting{false};
std::mutex protected_mutex;
std::set<std::pair<dev_t, ino_t>>& ProtectedFiles() {
  static std::set<std::pair<dev_t, ino_t>> files;
  return files;
}

}  // namespace

void ProtectInputs() { protecting = true; }

bool IsProtectedInput(const std::string& path) {
  struct stat status {};
  if (!protecting || ::stat(path.c_str(), &status) != 0) return false;
  const std::lock_guard<std::mutex> lock(protected_mutex);
  return ProtectedFiles().count({status.st_dev, status.st_ino}) > 0;
}

void CheckRegularInputFile(const std::string& path, const std::string& what) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (!fs::exists(status)) throw FileError(path, "cannot open " + what + " (no such file)");
  if (!fs::is_regular_file(status))
    throw FileError(path, std::string("is ") + TypeName(status.type()) + ", not a " + what);
  struct stat file {};
  if (protecting && ::stat(path.c_str(), &file) == 0) {
    const std::lock_guard<std::mutex> lock(protected_mutex);
    ProtectedFiles().insert({file.st_dev, file.st_ino});
  }
}

std::string ReadFileBytes(const std::string& path, const std::string& what, std::size_t max_bytes) {
  CheckRegularInputFile(path, what);
  std::error_code error;
  const std::uintmax_t size = fs::file_size(path, error);
  if (!error && size > max_bytes) {
    throw FileError(path, what + " of " + std::to_string(size) + " bytes, more than " + std::to_string(max_bytes));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError(path, "cannot open " + what);
  try {
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw FileError(path, "read error");
    if (bytes.size() > max_bytes) throw FileError(path, what + " larger than " + std::to_string(max_bytes) + " bytes");
    return bytes;
  } catch (const std::ios_base::failure&) {
    throw FileError(path, "read error");
  }
}

}  // namespace radargauss
