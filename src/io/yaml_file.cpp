// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/yaml_file.hpp"

#include <algorithm>
#include <map>
#include <vector>

#include "radargauss/error.hpp"
#include "radargauss/io/read_file.hpp"

namespace radargauss {

namespace {

std::size_t LineOf(const YAML::Node& node) { return std::size_t(node.Mark().line + 1); }

// Refuses a key given twice in any map of `node`, and nesting beyond the bound.
void CheckKeysAndDepth(const YAML::Node& node, const std::string& path, int depth) {
  if (depth > kMaxConfigDepth) {
    throw FileError(path, LineOf(node), "nested more than " + std::to_string(kMaxConfigDepth) + " levels");
  }
  if (node.IsMap()) {
    std::map<std::string, std::size_t> lines;
    for (const auto& entry : node) {
      if (entry.first.IsScalar()) {
        const auto [it, inserted] = lines.emplace(entry.first.Scalar(), LineOf(entry.first));
        if (!inserted) {
          throw FileError(path, LineOf(entry.first), "key '" + entry.first.Scalar() + "' given twice (first on line " +
                                                         std::to_string(it->second) + ")");
        }
      }
      CheckKeysAndDepth(entry.second, path, depth + 1);
    }
  } else if (node.IsSequence()) {
    for (const auto& element : node) CheckKeysAndDepth(element, path, depth + 1);
  }
}

}  // namespace

YAML::Node ReadYamlDocument(const std::string& path, const std::string& what) {
  const std::string text = ReadFileBytes(path, what, kMaxConfigFileBytes);
  std::vector<YAML::Node> documents;
  try {
    documents = YAML::LoadAll(text);
  } catch (const YAML::Exception& e) {
    throw FileError(path, std::size_t(e.mark.line + 1), "YAML: " + e.msg);
  }
  // An empty document after '---' adds nothing; one with content would be ignored silently.
  const auto with_content = [](const YAML::Node& document) { return !document.IsNull(); };
  if (documents.size() > 1 && std::any_of(documents.begin() + 1, documents.end(), with_content)) {
    throw FileError(path, "a second YAML document after '---' (a " + what + " is one document)");
  }
  if (documents.empty()) return YAML::Node();
  CheckKeysAndDepth(documents.front(), path, 0);
  return documents.front();
}

}  // namespace radargauss
