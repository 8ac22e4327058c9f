// SPDX-License-Identifier: BSD-3-Clause
// YAML configuration files for the radargauss command-line tool, through
// CLI11's config interface: every flag of a subcommand can be set in a YAML
// map (keys are the long flag names without "--"), and flags given on the
// command line override the file. Lists may be YAML sequences.
//
//   # configs/synthetic_world_localize.yaml
//   w-rcs: [0, 0.1, 0.25]
//   solver: gn
#pragma once

#include <CLI/CLI.hpp>
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "radargauss/core/error.hpp"
#include "radargauss/io/yaml_file.hpp"

namespace radargauss {

class YamlConfig final : public CLI::Config {
 public:
  // `section`: the subcommand the keys belong to (CLI11 2.1 reads config
  // files on the main app only, so the items are addressed to it); `path`:
  // the file, for the messages.
  YamlConfig(std::string section, std::string path) : section_(std::move(section)), path_(std::move(path)) {}

  std::string to_config(const CLI::App*, bool, bool, std::string) const override { return {}; }

  // Reads the file by its path (bounded, one document, no key twice), not
  // the stream CLI11 opened: docs/design/formats.md, "Bounds on input".
  std::vector<CLI::ConfigItem> from_config(std::istream&) const override {
    YAML::Node root;
    try {
      root = ReadYamlDocument(path_, "configuration file");
    } catch (const DataError& e) {
      throw CLI::ConversionError(e.what());
    }
    std::vector<CLI::ConfigItem> items;
    if (root.IsNull()) return items;
    if (!root.IsMap()) throw Error("expected a map of flag: value");
    for (const auto& entry : root) {
      CLI::ConfigItem item;
      if (!section_.empty()) item.parents = {section_};
      const YAML::Node& value = entry.second;
      if (!entry.first.IsScalar()) throw Error("line " + Line(entry.first) + ": a key must be a flag name");
      item.name = entry.first.Scalar();
      if (value.IsSequence()) {
        for (const auto& element : value) {
          if (!element.IsScalar()) throw Error("'" + item.name + "' (line " + Line(element) + "): a list of values");
          item.inputs.push_back(element.Scalar());
        }
      } else if (value.IsScalar()) {
        item.inputs.push_back(value.Scalar());
      } else {
        throw Error("'" + item.name + "' must be a value or a list");
      }
      items.push_back(std::move(item));
    }
    return items;
  }

 private:
  CLI::ConversionError Error(const std::string& what) const { return CLI::ConversionError(path_ + ": " + what); }
  static std::string Line(const YAML::Node& node) { return std::to_string(node.Mark().line + 1); }

  std::string section_;
  std::string path_;
};

}  // namespace radargauss
