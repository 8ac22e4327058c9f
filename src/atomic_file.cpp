// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/atomic_file.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>

#include "radargauss/error.hpp"

namespace radargauss {

namespace {

namespace fs = std::filesystem;

// Removes the "<name>.tmp.<pid>" files of `directory` whose process has
// ended (killed during a write), once per directory and process.
void RemoveStaleTemporaries(const fs::path& directory) {
  static std::mutex mutex;
  static std::set<fs::path> cleaned;
  const std::lock_guard<std::mutex> lock(mutex);
  if (!cleaned.insert(directory).second) return;
  std::error_code error;
  for (fs::directory_iterator it(directory.empty() ? fs::path(".") : directory, error), end; !error && it != end;
       it.increment(error)) {
    const std::string name = it->path().filename().string();
    const std::size_t mark = name.rfind(".tmp.");
    if (mark == std::string::npos || mark + 5 == name.size()) continue;
    const std::string digits = name.substr(mark + 5);
    if (digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 9) continue;
    const pid_t pid = pid_t(std::stol(digits));
    if (pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH) {
      std::error_code ignored;
      fs::remove(it->path(), ignored);
    }
  }
}

}  // namespace

void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write, bool binary) {
  RemoveStaleTemporaries(fs::path(path).parent_path());
  const std::string temporary = path + ".tmp." + std::to_string(::getpid());
  try {
    {
      std::ofstream out(temporary, binary ? std::ios::out | std::ios::binary : std::ios::out);
      if (!out) throw FileError(path, "cannot open for writing");
      write(out);
      out.flush();
      if (!out) throw FileError(path, "write failed");
    }
    if (std::rename(temporary.c_str(), path.c_str()) != 0) {
      throw FileError(path, "cannot rename temporary file into place");
    }
  } catch (...) {
    std::remove(temporary.c_str());
    throw;
  }
}

}  // namespace radargauss
