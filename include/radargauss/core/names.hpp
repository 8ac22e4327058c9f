// SPDX-License-Identifier: BSD-3-Clause
// Enum values by name: every named option (losses, solvers, incidence models,
// coarse levels, map builders) keeps one table of (value, name) pairs, and
// its parser, its printer and the lists the tool offers come from it.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace radargauss {

template <typename Enum>
using NamedValue = std::pair<Enum, const char*>;

// `names` as one list, "a, b, c": help texts, messages and docstrings.
inline std::string Joined(const std::vector<std::string>& names, const char* separator = ", ") {
  std::string joined;
  for (const std::string& name : names) joined += (joined.empty() ? "" : separator) + name;
  return joined;
}

// Every name of `table`, in its order.
template <typename Enum, std::size_t N>
std::vector<std::string> NamesOf(const NamedValue<Enum> (&table)[N]) {
  std::vector<std::string> names;
  for (const auto& entry : table) names.push_back(entry.second);
  return names;
}

// The value named `name`; throws std::invalid_argument naming `what` and the choices.
template <typename Enum, std::size_t N>
Enum ValueNamed(const NamedValue<Enum> (&table)[N], const std::string& name, const char* what) {
  for (const auto& [value, entry_name] : table) {
    if (name == entry_name) return value;
  }
  throw std::invalid_argument("unknown " + std::string(what) + " '" + name + "' (" + Joined(NamesOf(table)) + ")");
}

// The name of `value` ("unknown" for a value outside the table).
template <typename Enum, std::size_t N>
std::string NameOf(const NamedValue<Enum> (&table)[N], Enum value) {
  for (const auto& [entry_value, name] : table) {
    if (entry_value == value) return name;
  }
  return "unknown";
}

}  // namespace radargauss
