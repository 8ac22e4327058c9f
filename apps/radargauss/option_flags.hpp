// SPDX-License-Identifier: BSD-3-Clause
// The flags of an option table (radargauss/options.hpp): one per option,
// named, ranged and defaulted as the table says, so that the flags, the YAML
// keys (the flags without "--") and the library's validation cannot drift
// apart. --help shows the sensor group; --help-all every group.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

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

}  // namespace radargauss::cli
