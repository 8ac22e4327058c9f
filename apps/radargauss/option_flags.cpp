// SPDX-License-Identifier: BSD-3-Clause
#include "option_flags.hpp"

#include <cctype>
#include <cstdio>
#include <map>
#include <utility>

namespace radargauss::cli {

namespace {
bool show_every_option = false;
}  // namespace

void CheckAfterParse(CLI::App* app, std::function<void()> check) {
  static std::map<CLI::App*, std::vector<std::function<void()>>> checks;
  std::vector<std::function<void()>>& of_app = checks[app];
  of_app.push_back(std::move(check));
  if (of_app.size() > 1) return;  // the callback below runs them all
  app->final_callback([&of_app] {
    try {
      for (const std::function<void()>& run : of_app) run();
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError(e.what());
    }
  });
}

CLI::Option* AddBoolFlag(CLI::App* app, const std::string& name, std::function<void(bool)> set,
                         const std::string& help) {
  CLI::Option* flag = app->add_option(
      name,
      [name, set](const CLI::results_t& words) {
        try {
          set(ParseFlagWord(words.empty() ? std::string("true") : words.back()));
        } catch (const std::invalid_argument& e) {
          throw CLI::ValidationError(name, e.what());
        }
        return true;
      },
      help);
  // No value but with '=' (a flag), the last of several given wins.
  flag->expected(0)->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  return flag;
}

CLI::Option* AddBoolFlag(CLI::App* app, const std::string& name, bool& target, const std::string& help) {
  return AddBoolFlag(
      app, name, [&target](bool on) { target = on; }, help);
}

void ShowEveryOption(bool show) { show_every_option = show; }
bool ShowingEveryOption() { return show_every_option; }

std::string HelpGroup(OptionGroup group) {
  switch (group) {
    case OptionGroup::kSensor:
      return "Sensor and method";
    case OptionGroup::kTuning:
      return "Tuning";
    case OptionGroup::kStudy:
      return "Study";
  }
  return "Tuning";
}

const char* const kListedElsewhereGroup = "Listed elsewhere";

void WarnDeprecated(const std::string& old_flag, const std::string& flag) {
  std::fprintf(stderr, "radargauss: warning: %s is deprecated: use %s\n", old_flag.c_str(), flag.c_str());
}

void AddFooterLine(CLI::App* app, const std::string& line) {
  const std::string footer = app->get_footer();
  if (footer.find(line) != std::string::npos) return;
  app->footer(footer.empty() ? line : footer + "\n" + line);
}

std::string GroupedHelp::make_group(std::string group, bool is_positional, std::vector<const CLI::Option*> opts) const {
  if (group == kListedElsewhereGroup) return {};
  if (!show_every_option && (group == HelpGroup(OptionGroup::kTuning) || group == HelpGroup(OptionGroup::kStudy))) {
    return {};
  }
  return CLI::Formatter::make_group(std::move(group), is_positional, std::move(opts));
}

std::string GroupedHelp::make_help(const CLI::App* app, std::string name, CLI::AppFormatMode mode) const {
  std::string help = CLI::Formatter::make_help(app, std::move(name), mode);
  for (std::size_t blank = help.find("\n\n\n"); blank != std::string::npos; blank = help.find("\n\n\n", blank)) {
    help.erase(blank, 1);
  }
  return help;
}

std::string HelpText(const OptionSpec& option) {
  std::string text = option.help;
  if (!text.empty()) text[0] = char(std::toupper(static_cast<unsigned char>(text[0])));
  if (!option.unit.empty()) text += " (" + option.unit + ")";
  if (!option.at_least.empty()) {
    OptionSpec other;
    other.name = option.at_least;
    text += "; at least " + other.Flag();
  }
  return text;
}

}  // namespace radargauss::cli
