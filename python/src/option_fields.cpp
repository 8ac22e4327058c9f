// SPDX-License-Identifier: BSD-3-Clause
#include "option_fields.hpp"

#include <pybind11/stl.h>

#include <cmath>
#include <vector>

#include "radargauss/core/names.hpp"

namespace radargauss::python {

namespace {

double NumberFromPython(const py::handle& value, const std::string& keyword) {
  if (py::isinstance<py::bool_>(value) ||
      !(py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value) || py::hasattr(value, "__float__"))) {
    throw py::type_error(keyword + " must be a number");
  }
  return value.cast<double>();
}

}  // namespace

OptionValue ValueFromPython(const OptionSpec& option, const py::handle& value) {
  const std::string& keyword = option.name;
  OptionValue out;
  switch (option.kind) {
    case OptionKind::kFlag:
      if (!py::isinstance<py::bool_>(value)) throw py::type_error(keyword + " must be a bool");
      out = value.cast<bool>();
      break;
    case OptionKind::kInteger:
      if (py::isinstance<py::bool_>(value) || !py::isinstance<py::int_>(value)) {
        throw py::type_error(keyword + " must be an int");
      }
      try {
        out = std::int64_t(value.cast<long long>());
      } catch (const py::cast_error&) {
        throw py::value_error(keyword + " is out of range");
      }
      break;
    case OptionKind::kReal:
      out = NumberFromPython(value, keyword);
      break;
    case OptionKind::kChoice:
      if (!py::isinstance<py::str>(value)) throw py::type_error(keyword + " must be a str");
      out = value.cast<std::string>();
      break;
    case OptionKind::kReals: {
      if (option.unit_quaternion) {
        out = option_detail::PoseWords(PoseFromPython(value, keyword));
        break;
      }
      if (py::isinstance<py::str>(value)) throw py::type_error(keyword + " must be a sequence of numbers");
      std::vector<double> list;
      for (const py::handle item : py::iter(value)) list.push_back(NumberFromPython(item, keyword));
      out = list;
      break;
    }
  }
  const std::string why = option.Check(out);
  if (!why.empty()) throw py::value_error(keyword + " = " + FormatOptionValue(out) + " " + why);
  return out;
}

py::object ValueToPython(const OptionSpec& option, const OptionValue& value) {
  if (option.unit_quaternion) return PoseToMatrix(option_detail::PoseFromWords(std::get<std::vector<double>>(value)));
  return std::visit([](const auto& v) { return py::object(py::cast(v)); }, value);
}

std::string TypeDoc(const OptionSpec& option) {
  switch (option.kind) {
    case OptionKind::kFlag:
      return "bool";
    case OptionKind::kInteger:
      return "int";
    case OptionKind::kReal:
      return "float";
    case OptionKind::kChoice:
      return "{'" + Joined(option.choices, "', '") + "'}";
    case OptionKind::kReals:
      if (option.unit_quaternion) return "array (4, 4) or (7,)";
      return option.min_count == option.max_count ? "sequence of " + std::to_string(option.min_count) + " float"
                                                  : "list of float";
  }
  return "object";
}

}  // namespace radargauss::python
