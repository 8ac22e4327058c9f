// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/yaml_file.hpp"

#include <yaml-cpp/eventhandler.h>

#include <map>
#include <sstream>
#include <utility>
#include <vector>

#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"

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
          throw FileError(
              path, LineOf(entry.first),
              "key '" + entry.first.Scalar() + "' given twice (first on line " + std::to_string(it->second) + ")");
        }
      }
      CheckKeysAndDepth(entry.second, path, depth + 1);
    }
  } else if (node.IsSequence()) {
    for (const auto& element : node) CheckKeysAndDepth(element, path, depth + 1);
  }
}

// The first document's content and its node count with every alias
// expanded, counted from the parser's events (never from the loaded tree,
// whose walk an alias of an alias of ... makes exponential). An anchor's
// count is known when its node ends; an alias adds it again.
class DocumentCensus final : public YAML::EventHandler {
 public:
  DocumentCensus(const std::string& path, std::size_t max_nodes) : path_(path), max_nodes_(max_nodes) {}
  bool found = false;
  std::size_t nodes = 0;

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override { Leaf(mark, anchor); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    found = true;
    const auto it = anchored_.find(anchor);
    Add(mark, it == anchored_.end() ? 1 : it->second);
  }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor, const std::string&) override {
    found = true;
    Leaf(mark, anchor);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    Open(mark, anchor);
  }
  void OnSequenceEnd() override { Close(); }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    Open(mark, anchor);
  }
  void OnMapEnd() override { Close(); }

 private:
  void Add(const YAML::Mark& mark, std::size_t count) {
    nodes += count;
    if (nodes > max_nodes_) {
      throw FileError(path_, std::size_t(mark.line + 1),
                      "more than " + std::to_string(max_nodes_) + " YAML nodes with aliases expanded");
    }
  }
  void Leaf(const YAML::Mark& mark, YAML::anchor_t anchor) {
    Add(mark, 1);
    if (anchor != YAML::NullAnchor) anchored_[anchor] = 1;
  }
  void Open(const YAML::Mark& mark, YAML::anchor_t anchor) {
    found = true;
    open_.push_back({anchor, nodes});
    Add(mark, 1);
  }
  void Close() {
    const auto [anchor, start] = open_.back();
    open_.pop_back();
    if (anchor != YAML::NullAnchor) anchored_[anchor] = nodes - start;
  }

  std::string path_;
  std::size_t max_nodes_;
  std::vector<std::pair<YAML::anchor_t, std::size_t>> open_;  // each open node's anchor and the count at its start
  std::map<YAML::anchor_t, std::size_t> anchored_;            // each anchored node's expanded count
};

// Counts the first document's nodes (throws past kMaxConfigNodes) and tells
// whether a document with content follows it. The parser is driven document
// by document with a bound: YAML::LoadAll never ends on some malformed inputs (", ").
bool CensusAndSecondDocument(const std::string& text, const std::string& path) {
  std::istringstream input(text);
  YAML::Parser parser(input);
  DocumentCensus first(path, kMaxConfigNodes);
  if (!parser.HandleNextDocument(first)) return false;
  for (int document = 1; document < 8; ++document) {
    DocumentCensus next(path, kMaxConfigNodes);
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
    // The census first: it bounds the walks that follow (the key check, the readers).
    if (CensusAndSecondDocument(text, path)) {
      throw FileError(path, "more than one YAML document (a " + what + " is one)");
    }
    document = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw FileError(path, std::size_t(e.mark.line + 1), "YAML: " + e.msg);
  }
  CheckKeysAndDepth(document, path, 0);
  return document;
}

}  // namespace radargauss
