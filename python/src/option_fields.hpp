// SPDX-License-Identifier: BSD-3-Clause
// The options of `match` and `RadarOdometry` as Python keywords, from one
// table per options struct (option_fields.cpp): the keywords, the values
// they set, the docstrings' Parameters and the dicts read back all come from
// it. Each entry names the C++ member it sets (`path`, as written in C++).
//
// Keywords: a ScanMatchingOptions field by its own name (losses as loss,
// loss_scale, rcs_loss, rcs_loss_scale); the solvers' own options as gn_*,
// ceres_*, mh_*; odometry's own by name, its Doppler filter as ego_*, its
// map as region*, refit_growth, active_radius, gaussians_*, rcs_*, map_*.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "convert.hpp"
#include "radargauss/odometry/radar_odometry.hpp"

namespace radargauss::python {

template <typename Options>
struct OptionField {
  std::string keyword;  // the Python keyword
  std::string path;     // the C++ member it sets, e.g. "matching.gate"
  std::string type;     // numpydoc type: float, int, bool, str, ...
  std::string doc;
  std::function<void(Options&, const py::handle&)> set;  // TypeError or ValueError for a bad value
  std::function<py::object(const Options&)> get;
};

const std::vector<OptionField<MatchOptions>>& MatchFields();
// Odometry's own fields, then every match field (paths under match.).
const std::vector<OptionField<OdometryOptions>>& OdometryFields();

// `options` with each keyword of `kwargs` set; a TypeError names an unknown keyword.
template <typename Options>
Options OptionsFrom(const std::vector<OptionField<Options>>& fields, const py::kwargs& kwargs, Options options = {}) {
  for (const auto& [key, value] : kwargs) {
    const std::string keyword = py::str(key);
    const OptionField<Options>* field = nullptr;
    for (const OptionField<Options>& f : fields) {
      if (f.keyword == keyword) field = &f;
    }
    if (!field) throw py::type_error("unknown keyword '" + keyword + "' (option_fields() lists them)");
    field->set(options, value);
  }
  return options;
}

// Every field of `options` by keyword.
template <typename Options>
py::dict OptionsToDict(const std::vector<OptionField<Options>>& fields, const Options& options) {
  py::dict out;
  for (const OptionField<Options>& f : fields) out[py::str(f.keyword)] = f.get(options);
  return out;
}

// numpydoc Parameters lines: "name : type, default <value>" and the doc, indented.
template <typename Options>
std::string ParametersDoc(const std::vector<OptionField<Options>>& fields) {
  std::string doc;
  const Options defaults{};
  for (const OptionField<Options>& f : fields) {
    doc += f.keyword + " : " + f.type + ", default " + py::repr(f.get(defaults)).template cast<std::string>() +
           "\n    " + f.doc + "\n";
  }
  return doc;
}

// The table as Python sees it: one dict per field (keyword, path, type, doc, default).
template <typename Options>
py::list FieldsToList(const std::vector<OptionField<Options>>& fields) {
  py::list out;
  const Options defaults{};
  for (const OptionField<Options>& f : fields) {
    py::dict d;
    d["keyword"] = f.keyword;
    d["path"] = f.path;
    d["type"] = f.type;
    d["doc"] = f.doc;
    d["default"] = f.get(defaults);
    out.append(d);
  }
  return out;
}

}  // namespace radargauss::python
