// SPDX-License-Identifier: BSD-3-Clause
// Configuration files in YAML, read one way by the simulator and the
// command-line tool (docs/design/formats.md, "Bounds on input").
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <string>

namespace radargauss {

// A configuration file is a few kilobytes; this bound refuses a wrong file
// (a point cloud, /dev/zero's like) before it is parsed.
constexpr std::size_t kMaxConfigFileBytes = std::size_t(1) << 20;
// Maps and lists nested deeper than this are not a configuration.
constexpr int kMaxConfigDepth = 32;
// Nodes in the document with every alias expanded (a "billion laughs" of
// aliases of aliases is a few hundred bytes): counted before any walk.
constexpr std::size_t kMaxConfigNodes = std::size_t(1) << 18;

// The one YAML document in `path` ("<what>" in messages). Throws DataError
// naming the file (and the line where there is one) when it is not a regular
// file, exceeds kMaxConfigFileBytes, is not YAML, holds a second document,
// nests deeper than kMaxConfigDepth,
// holds more than kMaxConfigNodes nodes with its aliases expanded, or gives a key twice in one map.
YAML::Node ReadYamlDocument(const std::string& path, const std::string& what);

}  // namespace radargauss
