// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/atomic_file.hpp"

#include <unistd.h>

#include <cstdio>
#include <fstream>

#include "radargauss/error.hpp"

namespace radargauss {

void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write, bool binary) {
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
