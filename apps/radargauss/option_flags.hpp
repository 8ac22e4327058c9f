// SPDX-License-Identifier: BSD-3-Clause
// The flags of an option table (radargauss/options.hpp): one per option,
// named, ranged and defaulted as the table says, so that the flags, the YAML
// keys (the flags without "--") and the library's validation cannot drift
// apart. --help shows the sensor group; --help-all every group.
#pragma once

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "radargauss/core/names.hpp"
#include "radargauss/core/options.hpp"

namespace radargauss::cli {

// Whether --help shows every group (main sets it when --help-all is given).
void ShowEveryOption(bool show);
bool ShowingEveryOption();

// The group title an option is listed under.
std::string HelpGroup(OptionGroup group);

// CLI11's help with the tuning and study groups left out unless every
// option is shown (a hidden CLI11 option would lose its name in messages).
class GroupedHelp : public CLI::Formatter {
 public:
  std::string make_group(std::string group, bool is_positional, std::vector<const CLI::Option*> opts) const override;
  // CLI11's help without the blank lines the left-out groups leave.
  std::string make_help(const CLI::App* app, std::string name, CLI::AppFormatMode mode) const override;
};
// Runs `check` once `app`'s flags are all read (every check added to it, in
// order); a std::invalid_argument becomes a ValidationError.
void CheckAfterParse(CLI::App* app, std::function<void()> check);

// A flag that is on when given alone and takes one word with '=' (YAML: a
// value): true/false, 1/0, on/off, yes/no (ParseFlagWord); any other word
// is a ValidationError naming the flag. `set` gets the flag's value.
CLI::Option* AddBoolFlag(CLI::App* app, const std::string& name, std::function<void(bool)> set,
                         const std::string& help);
CLI::Option* AddBoolFlag(CLI::App* app, const std::string& name, bool& target, const std::string& help);

// "Std of the velocity term's floor Q (m); at least --x".
std::string HelpText(const OptionSpec& option);

// Rows a command reads like any other but whose --help-all leaves them to
// where they are listed in full: the tuning and study rows nested under
// `path` (another command's table: "odometry" in slam), and the rows named
// `echo_prefix` + n whose default is row n's ("verify_": the loop
// verification's match where it is the odometry's). `footer` says where.
struct ListedElsewhere {
  std::string path;
  std::string echo_prefix;
  std::string footer;
};
// The group such rows go to: never listed.
extern const char* const kListedElsewhereGroup;

// Appends `line` to the help's footer unless it is there already.
void AddFooterLine(CLI::App* app, const std::string& line);

// Whether `option` of `table` is one that `elsewhere` leaves out of the help.
template <typename Options>
bool IsListedElsewhere(const OptionTable<Options>& table, const Options& options, const Option<Options>& option,
                       const ListedElsewhere& elsewhere) {
  if (!elsewhere.path.empty() && option.group != OptionGroup::kSensor &&
      option.path.rfind(elsewhere.path + ".", 0) == 0) {
    return true;
  }
  if (elsewhere.echo_prefix.empty() || option.name.rfind(elsewhere.echo_prefix, 0) != 0) return false;
  const Option<Options>* echoed = FindOption(table, option.name.substr(elsewhere.echo_prefix.size()));
  return echoed != nullptr && FormatOptionValue(echoed->get(options)) == FormatOptionValue(option.get(options));
}

// A flag per option of `table`, setting `options` (which must outlive the
// parse); a value the table refuses is a ValidationError naming the flag.
template <typename Options>
void AddTableOptions(CLI::App* app, const OptionTable<Options>& table, Options& options,
                     const ListedElsewhere& elsewhere = {}) {
  bool left_out = false;
  for (const Option<Options>& entry : table) {
    const Option<Options>* option = &entry;  // the tables are static
    CLI::Option* flag = nullptr;
    if (option->kind == OptionKind::kFlag) {
      flag = AddBoolFlag(
          app, option->Flag(), [&options, option](bool on) { option->set(options, OptionValue(on)); },
          HelpText(*option));
    } else {
      flag = app->add_option(
          option->Flag(),
          [&options, option](const CLI::results_t& words) {
            try {
              option->set(options, option->Parse(words));
            } catch (const std::invalid_argument& e) {
              throw CLI::ValidationError(option->Flag(), e.what());
            }
            return true;
          },
          HelpText(*option));
      flag->type_name(option->TypeText() + ":" + option->RangeText());
      if (option->kind == OptionKind::kReals) {
        flag->expected(int(option->min_count), int(option->max_count));
      }
    }
    flag->default_str(FormatOptionValue(option->get(options)));
    const bool elsewhere_listed = IsListedElsewhere(table, options, *option, elsewhere);
    flag->group(elsewhere_listed ? kListedElsewhereGroup : HelpGroup(option->group));
    left_out = left_out || elsewhere_listed;
  }
  // What no single flag decides (an option below another) is checked once all are read.
  CheckAfterParse(app, [&table, &options] { CheckOptions(table, options, true); });
  if (!ShowingEveryOption()) AddFooterLine(app, "--help-all lists every option (the tuning and study groups too)");
  if (left_out && ShowingEveryOption()) AddFooterLine(app, elsewhere.footer);
  app->formatter(std::make_shared<GroupedHelp>());
}

// `table` without the rows named in `names` (those a command reads otherwise,
// as sweeps); the copy must outlive the parse (keep it static).
template <typename Options>
OptionTable<Options> TableWithout(const OptionTable<Options>& table, const std::vector<std::string>& names) {
  OptionTable<Options> rest;
  for (const Option<Options>& option : table) {
    if (std::find(names.begin(), names.end(), option.name) == names.end()) rest.push_back(option);
  }
  return rest;
}

// A sweep over the row `name` of `table`: its flag (and YAML key) takes a
// list, commas or words, each element parsed and checked by the row (or one
// of `extra`, words the row does not know: the PCL peers of a solver sweep),
// kept as written in `words` (whose contents are the default). Set one of
// them on an options value with SetRow.
template <typename Options>
CLI::Option* AddSweepOption(CLI::App* app, const OptionTable<Options>& table, const std::string& name,
                            std::vector<std::string>& words, const std::vector<std::string>& extra = {}) {
  const Option<Options>* option = FindOption(table, name);
  if (option == nullptr || option->kind == OptionKind::kFlag || option->kind == OptionKind::kReals) {
    throw std::logic_error("AddSweepOption: no row '" + name + "' of one value");
  }
  std::string range = option->RangeText();
  if (!extra.empty()) range.insert(range.size() - 1, "," + Joined(extra, ","));
  CLI::Option* flag = app->add_option(
      option->Flag(),
      [option, &words, extra](const CLI::results_t& given) {
        words.clear();
        for (const std::string& word : given) {
          if (std::find(extra.begin(), extra.end(), word) == extra.end()) {
            try {
              const std::string refused = option->Check(option->Parse({word}));
              if (!refused.empty()) throw std::invalid_argument(refused);
            } catch (const std::invalid_argument& e) {
              throw CLI::ValidationError(option->Flag(), e.what());
            }
          }
          words.push_back(word);
        }
        return true;
      },
      HelpText(*option) + "; a list sweeps it, one run per value");
  flag->type_name(option->TypeText() + ":" + range + "...");
  flag->expected(1, 1 << 16);
  flag->delimiter(',');
  flag->default_str(Joined(words, ","));
  flag->group(HelpGroup(OptionGroup::kSensor));
  return flag;
}

// Sets the row `name` of `table` on `options` to `word` (a sweep's element).
template <typename Options>
void SetRow(const OptionTable<Options>& table, const std::string& name, const std::string& word, Options& options) {
  const Option<Options>* option = FindOption(table, name);
  if (option == nullptr) throw std::logic_error("SetRow: no row '" + name + "'");
  option->set(options, option->Parse({word}));
}

// Says on stderr that `old_flag` is deprecated for `flag`.
void WarnDeprecated(const std::string& old_flag, const std::string& flag);

// An old name of the row `name` of `table`: read as the row's flag, with a
// warning that names the new one; left out of the help.
template <typename Options>
void AddDeprecatedAlias(CLI::App* app, const OptionTable<Options>& table, Options& options, const std::string& old_flag,
                        const std::string& name) {
  const Option<Options>* option = FindOption(table, name);
  if (option == nullptr) throw std::logic_error("AddDeprecatedAlias: no row '" + name + "'");
  CLI::Option* alias = nullptr;
  if (option->kind == OptionKind::kFlag) {
    alias = AddBoolFlag(
        app, old_flag,
        [&options, option, old_flag](bool on) {
          WarnDeprecated(old_flag, option->Flag());
          option->set(options, OptionValue(on));
        },
        "deprecated: " + option->Flag());
  } else {
    alias = app->add_option(
        old_flag,
        [&options, option, old_flag](const CLI::results_t& words) {
          WarnDeprecated(old_flag, option->Flag());
          try {
            const OptionValue value = option->Parse(words);
            const std::string refused = option->Check(value);
            if (!refused.empty()) throw std::invalid_argument(refused);
            option->set(options, value);
          } catch (const std::invalid_argument& e) {
            throw CLI::ValidationError(old_flag, e.what());
          }
          return true;
        },
        "deprecated: " + option->Flag());
    alias->type_name(option->TypeText());
  }
  alias->group(kListedElsewhereGroup);
}

}  // namespace radargauss::cli
