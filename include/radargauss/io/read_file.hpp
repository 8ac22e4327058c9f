// SPDX-License-Identifier: BSD-3-Clause
// Reading a whole input file, the one way every reader opens its file.
#pragma once

#include <string>

namespace radargauss {

// The file's bytes. Throws DataError naming the file when it is missing, a
// directory, or cannot be read ("<path>: cannot open <what>").
std::string ReadFileBytes(const std::string& path, const std::string& what = "file");

}  // namespace radargauss
