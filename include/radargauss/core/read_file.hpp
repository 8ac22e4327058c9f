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

// Outputs never replace inputs (docs/design/formats.md, "Bounds on input"): after
// ProtectInputs() (the command-line tool calls it first), every file that
// CheckRegularInputFile admits is remembered by its device and inode, and
// the writers of atomic_file.hpp refuse to replace or remove one of them.
// Off by default: a library user may read a map and write it back.
void ProtectInputs();
// Whether `path` is a file this process has read since ProtectInputs().
bool IsProtectedInput(const std::string& path);

// The file's bytes. Throws DataError naming the file when it is missing, not
// a regular file, larger than `max_bytes`, or cannot be read
// ("<path>: cannot open <what>").
std::string ReadFileBytes(const std::string& path, const std::string& what = "file",
                          std::size_t max_bytes = std::numeric_limits<std::size_t>::max());

}  // namespace radargauss
