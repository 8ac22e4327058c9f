// SPDX-License-Identifier: BSD-3-Clause
// radargauss: the command-line tool (docs/cli.md). Every subcommand prints a
// one-line error and exits non-zero on bad input (flags, files).
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "commands.hpp"
#include "option_flags.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"
#include "yaml_config.hpp"

namespace {

// The subcommand whose flags a --config file sets (CLI11 reads config files
// on the main app only): the first subcommand word on the command line.
// simulate's --config is the world's parameters, not its flags.
std::string ConfigSection(int argc, char** argv, const std::vector<std::string>& subcommands) {
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (std::find(subcommands.begin(), subcommands.end(), word) != subcommands.end()) {
      return word == "simulate" ? std::string() : word;
    }
  }
  return {};
}

// The file given to --config (empty without one).
std::string ConfigPath(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--config" && i + 1 < argc) return argv[i + 1];
    if (word.rfind("--config=", 0) == 0) return word.substr(9);
  }
  return {};
}

// --help-all is --help with every option group shown (option_flags.hpp).
std::vector<char*> HelpAllAsHelp(int argc, char** argv) {
  static char help[] = "--help";
  std::vector<char*> args(argv, argv + argc);
  for (char*& arg : args) {
    if (std::string(arg) == "--help-all") {
      radargauss::cli::ShowEveryOption(true);
      arg = help;
    }
  }
  return args;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace radargauss::cli;
  std::vector<char*> args = HelpAllAsHelp(argc, argv);
  argv = args.data();
  CLI::App app{"radargauss: 4D radar Gaussian-RCS maps and scan matching"};
  app.require_subcommand(1);
  const std::vector<Subcommand> subcommands = {
      AddInfo(app),       AddSimulate(app), AddSimulateImu(app), AddBuildMap(app), AddMapInfo(app),
      AddLocalize(app),   AddEvaluate(app), AddRefine(app),      AddOdometry(app), AddSlam(app),
      AddRelocalize(app), AddMerge(app),    AddConvert(app),     AddExport(app),   AddCalibrate(app)};
  std::vector<std::string> names;
  for (const Subcommand& command : subcommands) names.push_back(command.app->get_name());
  int threads = 0;
  app.add_option("--threads", threads, "Worker threads (0: all cores)")->check(NonNegative());
  // Every subcommand but simulate (whose --config is the world's parameters)
  // reads a YAML file of its flags with --config; flags given on the command
  // line override the file.
  const std::string config_path = ConfigPath(argc, argv);
  app.set_config("--config", "", "YAML file of the subcommand's flags (all but simulate)");
  app.config_formatter(std::make_shared<radargauss::YamlConfig>(ConfigSection(argc, argv, names), config_path));
  app.allow_config_extras(CLI::config_extras_mode::error);
  for (const Subcommand& command : subcommands) {
    if (command.app->get_name() != "simulate") command.app->fallthrough();
  }
  CheckEveryNumberIsFinite(app);
  try {
    // By type before CLI11 opens it: a FIFO would block, /dev/zero never end.
    if (!config_path.empty()) radargauss::CheckRegularInputFile(config_path, "configuration file");
    app.parse(argc, argv);
  } catch (const radargauss::DataError& e) {
    std::fprintf(stderr, "radargauss: error: %s\n", radargauss::Printable(e.what()).c_str());
    return 2;
  } catch (const CLI::ConfigError& e) {
    // CLI11 names the file "INI" and the key section.key.
    const std::string extra = "INI was not able to parse ";
    std::string what = e.what();
    if (what.rfind(extra, 0) == 0) what = "unknown flag '" + what.substr(what.find('.') + 1) + "'";
    std::fprintf(stderr, "radargauss: error: %s: %s\n", radargauss::Printable(config_path).c_str(),
                 radargauss::Printable(what).c_str());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "radargauss: error: %s: out of memory\n", radargauss::Printable(config_path).c_str());
    return 2;
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    std::fprintf(stderr, "radargauss: error: %s\n", radargauss::Printable(e.what()).c_str());
    return e.get_exit_code();
  }
  std::unique_ptr<tbb::global_control> thread_limit;
  if (threads > 0) {
    thread_limit =
        std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  }
  try {
    radargauss::ProtectInputs();
    for (const Subcommand& command : subcommands) {
      if (!command.app->parsed()) continue;
      CheckRunPaths(*command.app, config_path);
      return command.run();
    }
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "radargauss: error: out of memory (an input larger than this machine can hold?)\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "radargauss: error: %s\n", radargauss::Printable(e.what()).c_str());
    return 1;
  }
  return 0;
}
