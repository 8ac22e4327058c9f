// SPDX-License-Identifier: BSD-3-Clause
// Reading a whole input file, the one way every reader opens its file.
#pragma once

#include <cstddef>
#include <limits>
#include <string>

namespace radargauss {

// Throws DataError naming the file unless `path` is a regular file (or a
// link to one): a directory, a character device such as /dev/zero, a FIFO
// or a socket is refused by its type before anything is read.
void CheckRegularInputFile(const std::string& path, const std::string& what = "file");

// The file's bytes. Throws DataError naming the file when it is missing, not
// a regular file, larger than `max_bytes`, or cannot be read
// ("<path>: cannot open <what>").
std::string ReadFileBytes(const std::string& path, const std::string& what = "file",
                          std::size_t max_bytes = std::numeric_limits<std::size_t>::max());

}  // namespace radargauss
