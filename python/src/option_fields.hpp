// SPDX-License-Identifier: BSD-3-Clause
// Python keywords from the option tables (radargauss/options.hpp): the
// keywords, the values they set, the docstrings' Parameters and the dicts
// read back all come from the table of the options struct, as the command
// line's flags do.
#pragma once

#include <string>

#include "convert.hpp"
#include "radargauss/core/options.hpp"

namespace radargauss::python {

// A Python value as `option` takes it, strictly: a bool is not a number, a
// float is finite, an integer fits; a pose is a (4, 4) matrix or 7 numbers.
// TypeError for the wrong type, ValueError for a value out of range.
OptionValue ValueFromPython(const OptionSpec& option, const py::handle& value);
py::object ValueToPython(const OptionSpec& option, const OptionValue& value);
std::string TypeDoc(const OptionSpec& option);  // numpydoc type: "float", "int", "{'gn', 'ceres'}", ...

// `options` with each keyword of `kwargs` set; a TypeError names an unknown keyword.
template <typename Options>
Options OptionsFrom(const OptionTable<Options>& table, const py::kwargs& kwargs, Options options = {}) {
  for (const auto& [key, value] : kwargs) {
    const std::string keyword = py::str(key);
    const Option<Options>* option = FindOption(table, keyword);
    if (!option) throw py::type_error("unknown keyword '" + keyword + "' (option_fields() lists them)");
    option->set(options, ValueFromPython(*option, value));
  }
  return options;
}

// Every option of `options` by keyword.
template <typename Options>
py::dict OptionsToDict(const OptionTable<Options>& table, const Options& options) {
  py::dict out;
  for (const Option<Options>& option : table) out[py::str(option.name)] = ValueToPython(option, option.get(options));
  return out;
}

// numpydoc Parameters lines: "name : type, default <value>" and the help, indented.
template <typename Options>
std::string ParametersDoc(const OptionTable<Options>& table) {
  std::string doc;
  const Options defaults{};
  for (const Option<Options>& option : table) {
    const std::string unit = option.unit.empty() ? "" : " (" + option.unit + ")";
    doc += option.name + " : " + TypeDoc(option) + ", default " +
           py::repr(ValueToPython(option, option.get(defaults))).template cast<std::string>() + "\n    " + option.help +
           unit + "\n";
  }
  return doc;
}

// The table as Python sees it: one dict per option (keyword, path, type,
// doc, default, group, unit, range).
template <typename Options>
py::list FieldsToList(const OptionTable<Options>& table) {
  py::list out;
  const Options defaults{};
  for (const Option<Options>& option : table) {
    py::dict d;
    d["keyword"] = option.name;
    d["path"] = option.path;
    d["type"] = TypeDoc(option);
    d["doc"] = option.help;
    d["default"] = ValueToPython(option, option.get(defaults));
    d["group"] = ToString(option.group);
    d["unit"] = option.unit;
    d["range"] = option.RangeText();
    out.append(d);
  }
  return out;
}

}  // namespace radargauss::python
