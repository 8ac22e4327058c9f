// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/core/options.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>

#include "radargauss/core/names.hpp"

namespace radargauss {

namespace {

// The shortest text that reads back as `x` ("100" rather than "1e+02").
std::string Shortest(double x) {
  std::string best;
  char text[32];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(text, sizeof(text), "%.*g", digits, x);
    if (std::strtod(text, nullptr) != x && digits < 17) continue;
    if (best.empty() || std::string(text).size() < best.size()) best = text;
  }
  return best;
}

std::string Bound(double x) { return std::isinf(x) ? (x > 0 ? "inf" : "-inf") : Shortest(x); }

bool InRange(const OptionSpec& spec, double x) {
  return std::isfinite(x) && (spec.min_open ? x > spec.min : x >= spec.min) && x <= spec.max;
}

// A number's reason to be refused; empty when it is fine.
std::string CheckNumber(const OptionSpec& spec, double x) {
  if (!std::isfinite(x)) return "is not a finite number";
  return InRange(spec, x) ? std::string() : "is not in " + spec.RangeText();
}

}  // namespace

std::string ToString(OptionGroup group) {
  switch (group) {
    case OptionGroup::kSensor:
      return "sensor";
    case OptionGroup::kTuning:
      return "tuning";
    case OptionGroup::kStudy:
      return "study";
  }
  return "tuning";
}

std::string FormatOptionValue(const OptionValue& value) {
  if (const bool* flag = std::get_if<bool>(&value)) return *flag ? "true" : "false";
  if (const std::int64_t* n = std::get_if<std::int64_t>(&value)) return std::to_string(*n);
  if (const double* x = std::get_if<double>(&value)) return Shortest(*x);
  if (const std::string* s = std::get_if<std::string>(&value)) return *s;
  std::string out = "[";
  for (const double x : std::get<std::vector<double>>(value)) out += (out.size() > 1 ? "," : "") + Shortest(x);
  return out + "]";
}

std::string OptionSpec::Flag() const {
  std::string flag = "--" + name;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

std::string OptionSpec::RangeText() const {
  if (kind == OptionKind::kFlag) return {};
  if (kind == OptionKind::kChoice) return "{" + Joined(choices, ",") + "}";
  return (min_open ? "(" : "[") + Bound(min) + ", " + Bound(max) + (std::isinf(max) ? ")" : "]");
}

std::string OptionSpec::TypeText() const {
  switch (kind) {
    case OptionKind::kFlag:
      return "FLAG";
    case OptionKind::kInteger:
      return "INT";
    case OptionKind::kChoice:
      return "TEXT";
    default:
      return "FLOAT";
  }
}

std::string OptionSpec::Check(const OptionValue& value) const {
  switch (kind) {
    case OptionKind::kFlag:
      return std::holds_alternative<bool>(value) ? std::string() : "is not true or false";
    case OptionKind::kInteger:
      if (!std::holds_alternative<std::int64_t>(value)) return "is not an integer";
      return CheckNumber(*this, double(std::get<std::int64_t>(value)));
    case OptionKind::kReal:
      if (!std::holds_alternative<double>(value)) return "is not a number";
      return CheckNumber(*this, std::get<double>(value));
    case OptionKind::kChoice: {
      const std::string* word = std::get_if<std::string>(&value);
      if (!word || std::find(choices.begin(), choices.end(), *word) == choices.end()) {
        return "is not one of " + RangeText();
      }
      return {};
    }
    case OptionKind::kReals: {
      const std::vector<double>* list = std::get_if<std::vector<double>>(&value);
      if (!list) return "is not a list of numbers";
      if (list->size() < min_count || list->size() > max_count) {
        return min_count == max_count
                   ? "does not hold " + std::to_string(min_count) + " numbers"
                   : "does not hold " + std::to_string(min_count) + " to " + std::to_string(max_count) + " numbers";
      }
      for (const double x : *list) {
        const std::string why = CheckNumber(*this, x);
        if (!why.empty()) return "holds " + Shortest(x) + ", which " + why;
      }
      if (unit_quaternion) {
        const Eigen::Map<const Eigen::Vector4d> q(list->data() + list->size() - 4);
        if (!(std::abs(q.norm() - 1.0) < 1e-3))
          return "ends in no unit quaternion (its norm is " + Shortest(q.norm()) + ")";
      }
      return {};
    }
  }
  return {};
}

OptionValue OptionSpec::Parse(const std::vector<std::string>& words) const {
  const std::size_t wanted_min = kind == OptionKind::kReals ? min_count : 1;
  const std::size_t wanted_max = kind == OptionKind::kReals ? max_count : 1;
  if (words.size() < wanted_min || words.size() > wanted_max) {
    throw std::invalid_argument("takes " + std::to_string(wanted_min) +
                                (wanted_min == wanted_max ? "" : " to " + std::to_string(wanted_max)) + " value" +
                                (wanted_max == 1 ? "" : "s") + ", not " + std::to_string(words.size()));
  }
  // A number, refused in the words it was given: "1e300 is not in [0, 100]".
  const auto real = [this](const std::string& word) {
    char* end = nullptr;
    const double x = word.empty() ? NAN : std::strtod(word.c_str(), &end);
    if (word.empty() || *end != '\0') throw std::invalid_argument(word + " is not a number");
    const std::string why = CheckNumber(*this, x);
    if (!why.empty()) throw std::invalid_argument(word + " " + why);
    return x;
  };
  OptionValue value;
  switch (kind) {
    case OptionKind::kFlag: {
      value = ParseFlagWord(words[0]);
      break;
    }
    case OptionKind::kInteger: {
      char* end = nullptr;
      errno = 0;
      const long long n = std::strtoll(words[0].c_str(), &end, 10);
      if (words[0].empty() || *end != '\0' || errno == ERANGE) {
        throw std::invalid_argument(words[0] + " is not an integer");
      }
      const std::string why = CheckNumber(*this, double(n));
      if (!why.empty()) throw std::invalid_argument(words[0] + " " + why);
      value = std::int64_t(n);
      break;
    }
    case OptionKind::kReal:
      value = real(words[0]);
      break;
    case OptionKind::kChoice:
      value = words[0];
      if (std::find(choices.begin(), choices.end(), words[0]) == choices.end()) {
        throw std::invalid_argument(words[0] + " is not one of " + RangeText());
      }
      break;
    case OptionKind::kReals: {
      std::vector<double> list;
      for (const std::string& word : words) list.push_back(real(word));
      value = list;
      break;
    }
  }
  const std::string why = Check(value);
  if (!why.empty()) throw std::invalid_argument(FormatOptionValue(value) + " " + why);
  return value;
}

bool ParseFlagWord(const std::string& word) {
  std::string lower = word;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (lower == "true" || lower == "1" || lower == "on" || lower == "yes") return true;
  if (lower == "false" || lower == "0" || lower == "off" || lower == "no") return false;
  throw std::invalid_argument("'" + word + "' is not one of true/false, 1/0, on/off, yes/no");
}

namespace option_detail {

void RequireUniqueNames(const std::vector<std::string>& names) {
  std::set<std::string> seen;
  for (const std::string& name : names) {
    if (!seen.insert(name).second) throw std::logic_error("option " + name + " is in its table twice");
  }
}

double AsNumber(const OptionValue& value) {
  if (const std::int64_t* n = std::get_if<std::int64_t>(&value)) return double(*n);
  if (const double* x = std::get_if<double>(&value)) return *x;
  throw std::logic_error("an option compared with another is not a number");
}

std::vector<double> PoseWords(const SE3d& pose) {
  const Eigen::Vector3d t = pose.translation();
  const Eigen::Quaterniond q = pose.rotation().quaternion();
  return {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
}

SE3d PoseFromWords(const std::vector<double>& words) {
  const Eigen::Quaterniond q(words[6], words[3], words[4], words[5]);
  return SE3d(SO3d(q), Eigen::Vector3d(words[0], words[1], words[2]));
}

}  // namespace option_detail

}  // namespace radargauss
