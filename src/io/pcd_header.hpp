// SPDX-License-Identifier: BSD-3-Clause
// The PCD v0.7 header: its lines parsed and checked, the fields laid out.
// Internal to the PCD reader.
#pragma once

#include <string>
#include <vector>

#include "radargauss/io/pcd.hpp"

namespace radargauss::internal {

// The header at the start of `bytes` (the file `path`); throws FileError.
PcdHeader ParsePcdHeader(const std::string& path, const std::string& bytes);

// The whitespace-separated words of a line.
std::vector<std::string> SplitWords(const std::string& line);

}  // namespace radargauss::internal
