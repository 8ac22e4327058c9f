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

#include <sstream>
#include <string>
#include <vector>

namespace radargauss {

class YamlConfig final : public CLI::Config {
 public:
  // `section`: the subcommand the keys belong to (CLI11 2.1 reads config
  // files on the main app only, so the items are addressed to it).
  explicit YamlConfig(std::string section) : section_(std::move(section)) {}

  std::string to_config(const CLI::App*, bool, bool, std::string) const override { return {}; }

  std::vector<CLI::ConfigItem> from_config(std::istream& input) const override {
    std::stringstream text;
    text << input.rdbuf();
    YAML::Node root;
    try {
      root = YAML::Load(text.str());
    } catch (const YAML::Exception& e) {
      throw CLI::ConversionError(std::string("config file: YAML: ") + e.what());
    }
    std::vector<CLI::ConfigItem> items;
    if (root.IsNull()) return items;
    if (!root.IsMap()) throw CLI::ConversionError("config file: expected a map of flag: value");
    for (const auto& entry : root) {
      CLI::ConfigItem item;
      if (!section_.empty()) item.parents = {section_};
      item.name = entry.first.as<std::string>();
      const YAML::Node& value = entry.second;
      if (value.IsSequence()) {
        for (const auto& element : value) item.inputs.push_back(element.as<std::string>());
      } else if (value.IsScalar()) {
        item.inputs.push_back(value.as<std::string>());
      } else {
        throw CLI::ConversionError("config file: '" + item.name + "' must be a value or a list");
      }
      items.push_back(std::move(item));
    }
    return items;
  }

 private:
  std::string section_;
};

}  // namespace radargauss
