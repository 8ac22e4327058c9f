// SPDX-License-Identifier: BSD-3-Clause
// The files and folders a command writes, checked against each other and
// against every path it reads before the run starts (docs/design/formats.md,
// "Bounds on input"): an output never replaces an input.
#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/rig.hpp"

namespace radargauss::cli {

namespace {

namespace fs = std::filesystem;

// The flags that name what a command writes; the rest name what it reads.
const std::vector<std::string> kOutputFlags = {"--out", "--mcap", "--ply"};
// Commands whose --out is a file, not a results folder.
const std::vector<std::string> kFileOut = {"build-map", "convert"};

struct NamedPath {
  std::string flag, path;
};

bool SamePath(const std::string& a, const std::string& b) {
  std::error_code error;
  if (fs::exists(a, error) && fs::exists(b, error)) return fs::equivalent(a, b, error);
  const fs::path left = fs::weakly_canonical(fs::absolute(a), error);
  const fs::path right = fs::weakly_canonical(fs::absolute(b), error);
  return left.lexically_normal() == right.lexically_normal();
}

// The paths an option's values may name: the value, and a bag's path in
// "BAG:/topic[:child]".
std::vector<std::string> PathsOf(const std::string& value) {
  std::vector<std::string> paths{value};
  const std::size_t topic = value.find(":/");
  if (topic != std::string::npos && topic > 0) paths.push_back(value.substr(0, topic));
  return paths;
}

}  // namespace

void CheckRunPaths(const CLI::App& command, const std::string& config_path) {
  std::vector<NamedPath> outputs, inputs;
  if (!config_path.empty()) inputs.push_back({"--config", config_path});
  for (const CLI::Option* option : command.get_options()) {
    if (option->count() == 0) continue;
    const std::string flag = option->get_name();
    const bool output = std::find(kOutputFlags.begin(), kOutputFlags.end(), flag) != kOutputFlags.end();
    for (const std::string& value : option->results()) {
      if (value.empty()) continue;
      if (output) {
        outputs.push_back({flag, value});
        continue;
      }
      for (const std::string& path : PathsOf(value)) {
        std::error_code error;
        if (fs::exists(path, error)) inputs.push_back({flag, path});
      }
    }
  }
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const NamedPath& out = outputs[i];
    for (std::size_t j = i + 1; j < outputs.size(); ++j) {
      if (SamePath(out.path, outputs[j].path)) {
        throw DataError(out.flag + " and " + outputs[j].flag + " name the same path " + out.path);
      }
    }
    for (const NamedPath& in : inputs) {
      if (SamePath(out.path, in.path)) {
        throw DataError(out.flag + " " + out.path + " is also read (" + in.flag +
                        "); an output never replaces an input");
      }
    }
    const bool file =
        out.flag != "--out" || std::find(kFileOut.begin(), kFileOut.end(), command.get_name()) != kFileOut.end();
    if (file) {
      CheckOutputFile(out.path);
    } else {
      CheckOutputFolder(out.path);
    }
  }
}

void WriteRigWithAbsolutePaths(const std::string& path, Rig rig) {
  for (RigRadar& radar : rig.radars) {
    if (!radar.scans.sequence_dir.empty()) radar.scans.sequence_dir = fs::absolute(radar.scans.sequence_dir).string();
    if (!radar.scans.bag.empty()) radar.scans.bag = fs::absolute(radar.scans.bag).string();
  }
  WriteRig(path, rig);
}

}  // namespace radargauss::cli
