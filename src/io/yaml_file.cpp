// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/yaml_file.hpp"

#include <yaml-cpp/eventhandler.h>

#include <map>
#include <sstream>

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

// Whether a parsed document holds anything (an empty one is a lone null).
class DocumentContent final : public YAML::EventHandler {
 public:
  bool found = false;
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override { found = true; }
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override { found = true; }
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    found = true;
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    found = true;
  }
  void OnMapEnd() override {}
};

// Whether a document with content follows the first. The parser is driven
// document by document with a bound: YAML::LoadAll never ends on some
// malformed inputs (", ").
bool HasSecondDocument(const std::string& text) {
  std::istringstream input(text);
  YAML::Parser parser(input);
  DocumentContent first;
  if (!parser.HandleNextDocument(first)) return false;
  for (int document = 1; document < 8; ++document) {
    DocumentContent next;
    if (!parser.HandleNextDocument(next)) return false;
    if (next.found) return true;
  }
  return true;  // a parser that keeps finding documents: not one document
}

}  // namespace

YAML::Node ReadYamlDocument(const std::string& path, const std::string& what) {
  const std::string text = ReadFileBytes(path, what, kMaxConfigFileBytes);
  YAML::Node document;
  try {
    document = YAML::Load(text);
    if (HasSecondDocument(text)) {
      throw FileError(path, "more than one YAML document (a " + what + " is one)");
    }
  } catch (const YAML::Exception& e) {
    throw FileError(path, std::size_t(e.mark.line + 1), "YAML: " + e.msg);
  }
  CheckKeysAndDepth(document, path, 0);
  return document;
}

}  // namespace radargauss
