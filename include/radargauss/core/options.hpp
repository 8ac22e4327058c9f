// SPDX-License-Identifier: BSD-3-Clause
// One table per options struct (docs/design.md, "Options"): each option's
// name, group, unit, range and one line of help, and how to read and set it
// in the struct. The command line's flags and YAML keys, the Python keywords
// and docstrings, and the validation all come from the table.
//
//   const OptionTable<LocalMapOptions>& table = LocalMapOptionTable();
//   CheckOptions(table, options);  // std::invalid_argument naming the option
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "radargauss/lie/se3.hpp"

namespace radargauss {

// kSensor: what every user sets (the sensor, the method's main choices);
// kTuning: what an expert changes; kStudy: switches for experiments.
enum class OptionGroup { kSensor, kTuning, kStudy };
std::string ToString(OptionGroup group);  // "sensor", "tuning", "study"

enum class OptionKind { kFlag, kInteger, kReal, kChoice, kReals };

// A value as the interfaces hand it over: a flag, an integer, a real, a
// choice's name, or a list of reals (vectors, poses as x y z qx qy qz qw).
using OptionValue = std::variant<bool, std::int64_t, double, std::string, std::vector<double>>;
std::string FormatOptionValue(const OptionValue& value);  // "0.25", "[1,1,90]", "true", "gn"

// What an option is, whatever struct it sets.
struct OptionSpec {
  std::string name;  // snake_case: the Python keyword; the flag and YAML key are it with '-' for '_'
  std::string path;  // the member it sets, as written in C++ ("map.gaussians.min_std")
  OptionKind kind = OptionKind::kReal;
  OptionGroup group = OptionGroup::kTuning;
  std::string unit;  // "m", "deg", "m/s"; empty when it has none
  std::string help;
  // A number's range (each element of a list); an integer's is within its type's.
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;
  std::size_t min_count = 1, max_count = 1;  // a list's length
  std::vector<std::string> choices;          // kChoice
  std::string at_least;                      // another option of the table this one may not be below
  bool unit_quaternion = false;              // the list's last four numbers: a unit quaternion (a pose)

  std::string Flag() const;                           // "--region-capacity"
  std::string RangeText() const;                      // "[0, 1]", "(0, inf)", "{gn, ceres}"; empty for a flag
  std::string TypeText() const;                       // "FLOAT", "INT", "TEXT", "FLAG"
  std::string Check(const OptionValue& value) const;  // why `value` is refused; empty when it is fine
  // The value of the words a command line or YAML gave; std::invalid_argument saying why not.
  OptionValue Parse(const std::vector<std::string>& words) const;
};

// A flag's word as the command line and YAML give it: true/false, 1/0,
// on/off, yes/no in any case; std::invalid_argument for any other.
bool ParseFlagWord(const std::string& word);

template <typename Options>
struct Option : OptionSpec {
  std::function<OptionValue(const Options&)> get;
  std::function<void(Options&, const OptionValue&)> set;  // `value` as Check accepts it

  Option In(double lo, double hi) && { return min = lo, max = hi, std::move(*this); }
  Option Above(double lo) && { return min = lo, min_open = true, std::move(*this); }
  Option AtLeast(double lo) && { return min = lo, std::move(*this); }
  Option Count(std::size_t lo, std::size_t hi) && { return min_count = lo, max_count = hi, std::move(*this); }
  Option Unit(std::string u) && { return unit = std::move(u), std::move(*this); }
  Option Help(std::string h) && { return help = std::move(h), std::move(*this); }
  Option Sensor() && { return group = OptionGroup::kSensor, std::move(*this); }
  Option Study() && { return group = OptionGroup::kStudy, std::move(*this); }
  Option NotBelow(std::string other) && { return at_least = std::move(other), std::move(*this); }
  Option Choices(std::vector<std::string> names) && { return choices = std::move(names), std::move(*this); }
};

template <typename Options>
using OptionTable = std::vector<Option<Options>>;

// Throws std::invalid_argument "name = value: why" for the first option whose
// value the table refuses, and for an option below its `at_least`, naming
// both; by their flags ("--region-capacity") when `as_flags`.
template <typename Options>
void CheckOptions(const OptionTable<Options>& table, const Options& options, bool as_flags = false);

// The option of `table` named `name`, or nullptr.
template <typename Options>
const Option<Options>* FindOption(const OptionTable<Options>& table, const std::string& name) {
  for (const Option<Options>& option : table) {
    if (option.name == name) return &option;
  }
  return nullptr;
}

// `inner`'s options as options of the struct that holds it at `member`
// (`prefix`: the member's path), appended to `outer`, their names after
// `name_prefix`, but those named in `leave_out` (which the code sets).
// Throws std::logic_error when a name is taken twice.
template <typename Outer, typename Inner>
void AppendNested(OptionTable<Outer>& outer, const OptionTable<Inner>& inner, Inner& (*member)(Outer&),
                  const std::string& prefix, const std::string& name_prefix = "",
                  const std::vector<std::string>& leave_out = {});

namespace option_detail {

void RequireUniqueNames(const std::vector<std::string>& names);
double AsNumber(const OptionValue& value);        // an integer's or a real's; throws std::logic_error for others
std::vector<double> PoseWords(const SE3d& pose);  // x y z qx qy qz qw
SE3d PoseFromWords(const std::vector<double>& words);

template <typename T>
OptionValue ToValue(const T& value) {
  if constexpr (std::is_same_v<T, bool>) {
    return value;
  } else if constexpr (std::is_integral_v<T>) {
    return std::int64_t(value);
  } else if constexpr (std::is_floating_point_v<T>) {
    return double(value);
  } else if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
    return std::vector<double>{value.x(), value.y(), value.z()};
  } else if constexpr (std::is_same_v<T, SE3d>) {
    return PoseWords(value);
  } else {
    return value;  // std::vector<double>, std::string
  }
}

template <typename T>
T FromValue(const OptionValue& value) {
  if constexpr (std::is_same_v<T, bool>) {
    return std::get<bool>(value);
  } else if constexpr (std::is_integral_v<T>) {
    return T(std::get<std::int64_t>(value));
  } else if constexpr (std::is_floating_point_v<T>) {
    return T(std::get<double>(value));
  } else if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
    const std::vector<double>& v = std::get<std::vector<double>>(value);
    return Eigen::Vector3d(v[0], v[1], v[2]);
  } else if constexpr (std::is_same_v<T, SE3d>) {
    return PoseFromWords(std::get<std::vector<double>>(value));
  } else if constexpr (std::is_same_v<T, std::string>) {
    return std::get<std::string>(value);
  } else {
    return std::get<std::vector<double>>(value);
  }
}

}  // namespace option_detail

// An option of `Options` for the member `member` returns, its kind and
// range from the member's type: bool a flag, an integer within its type,
// Eigen::Vector3d three reals, SE3d a pose of seven, a string a choice
// (its names by Choices).
template <typename Options, typename T>
Option<Options> MakeOption(std::string name, std::string path, T& (*member)(Options&)) {
  Option<Options> option;
  option.name = std::move(name);
  option.path = std::move(path);
  if constexpr (std::is_same_v<T, bool>) {
    option.kind = OptionKind::kFlag;
  } else if constexpr (std::is_integral_v<T>) {
    constexpr double kLargest = 1e15;  // a count or seed beyond is a typo; below 2^53, each is a double
    option.kind = OptionKind::kInteger;
    option.min = std::max(double(std::numeric_limits<T>::min()), -kLargest);
    option.max = std::min(double(std::numeric_limits<T>::max()), kLargest);
  } else if constexpr (std::is_floating_point_v<T>) {
    option.kind = OptionKind::kReal;
  } else if constexpr (std::is_same_v<T, std::string>) {
    option.kind = OptionKind::kChoice;
  } else {
    option.kind = OptionKind::kReals;
    if constexpr (std::is_same_v<T, Eigen::Vector3d>) option.min_count = option.max_count = 3;
    if constexpr (std::is_same_v<T, SE3d>) option.min_count = option.max_count = 7, option.unit_quaternion = true;
    if constexpr (std::is_same_v<T, std::vector<double>>) option.min_count = 1, option.max_count = 64;
  }
  option.get = [member](const Options& o) { return option_detail::ToValue(member(const_cast<Options&>(o))); };
  option.set = [member](Options& o, const OptionValue& v) { member(o) = option_detail::FromValue<T>(v); };
  return option;
}

// An option for an enum member, by the names `names` lists and `from_name` reads.
template <typename Options, typename Enum>
Option<Options> MakeChoice(std::string name, std::string path, Enum& (*member)(Options&),
                           std::vector<std::string> names, Enum (*from_name)(const std::string&)) {
  Option<Options> option;
  option.name = std::move(name);
  option.path = std::move(path);
  option.kind = OptionKind::kChoice;
  option.choices = std::move(names);
  option.get = [member](const Options& o) { return OptionValue(ToString(member(const_cast<Options&>(o)))); };
  option.set = [member, from_name](Options& o, const OptionValue& v) {
    member(o) = from_name(std::get<std::string>(v));
  };
  return option;
}

// The member as a function pointer with its path spelled out once.
#define RADARGAUSS_OPTION(Options, name, member) \
  ::radargauss::MakeOption<Options>(             \
      name, #member, +[](Options & o) -> auto& { return o.member; })
#define RADARGAUSS_CHOICE(Options, name, member, names, from_name) \
  ::radargauss::MakeChoice<Options>(                               \
      name, #member, +[](Options & o) -> auto& { return o.member; }, names, from_name)

template <typename Options>
void CheckOptions(const OptionTable<Options>& table, const Options& options, bool as_flags) {
  const auto name = [as_flags](const OptionSpec& option) { return as_flags ? option.Flag() : option.name; };
  for (const Option<Options>& option : table) {
    const OptionValue value = option.get(options);
    const std::string why = option.Check(value);
    if (!why.empty()) throw std::invalid_argument(name(option) + " = " + FormatOptionValue(value) + " " + why);
    if (option.at_least.empty()) continue;
    const Option<Options>* other = FindOption(table, option.at_least);
    if (!other) throw std::logic_error(option.name + ": no option " + option.at_least + " in its table");
    const OptionValue bound = other->get(options);
    if (option_detail::AsNumber(value) < option_detail::AsNumber(bound)) {
      throw std::invalid_argument(name(option) + " (" + FormatOptionValue(value) + ") must be at least " +
                                  name(*other) + " (" + FormatOptionValue(bound) + ")");
    }
  }
}

template <typename Outer, typename Inner>
void AppendNested(OptionTable<Outer>& outer, const OptionTable<Inner>& inner, Inner& (*member)(Outer&),
                  const std::string& prefix, const std::string& name_prefix,
                  const std::vector<std::string>& leave_out) {
  for (const Option<Inner>& option : inner) {
    if (std::find(leave_out.begin(), leave_out.end(), option.name) != leave_out.end()) continue;
    Option<Outer> nested;
    static_cast<OptionSpec&>(nested) = option;
    nested.name = name_prefix + option.name;
    if (!nested.at_least.empty()) nested.at_least = name_prefix + option.at_least;
    nested.path = prefix + "." + option.path;
    nested.get = [member, get = option.get](const Outer& o) { return get(member(const_cast<Outer&>(o))); };
    nested.set = [member, set = option.set](Outer& o, const OptionValue& v) { set(member(o), v); };
    outer.push_back(std::move(nested));
  }
  std::vector<std::string> names;
  for (const Option<Outer>& option : outer) names.push_back(option.name);
  option_detail::RequireUniqueNames(names);
}

}  // namespace radargauss
