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

// A flag per option of `table`, setting `options` (which must outlive the
// parse); a value the table refuses is a ValidationError naming the flag.
template <typename Options>
void AddTableOptions(CLI::App* app, const OptionTable<Options>& table, Options& options) {
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
    flag->group(HelpGroup(option->group));
  }
  // What no single flag decides (an option below another) is checked once all are read.
  CheckAfterParse(app, [&table, &options] { CheckOptions(table, options, true); });
  if (!ShowingEveryOption()) app->footer("--help-all lists every option (the tuning and study groups too)");
  app->formatter(std::make_shared<GroupedHelp>());
}

}  // namespace radargauss::cli
