// SPDX-License-Identifier: BSD-3-Clause
// radargauss: the command-line tool (docs/cli.md). Every subcommand prints a
// one-line error and exits non-zero on bad input (flags, files).
#include <tbb/global_control.h>

#include <cstdio>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "commands.hpp"
#include "yaml_config.hpp"

namespace {

// The subcommand whose flags a --config file sets (CLI11 reads config files
// on the main app only): the first subcommand word on the command line.
std::string ConfigSection(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "info" || word == "build-map" || word == "localize" || word == "map-info" || word == "odometry") return word;
  }
  return {};
}

// The file given to the main app's --config, for the messages.
std::string ConfigPath(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--config" && i + 1 < argc) return argv[i + 1];
    if (word.rfind("--config=", 0) == 0) return word.substr(9);
  }
  return "config file";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace radargauss::cli;
  CLI::App app{"radargauss: 4D radar Gaussian-RCS maps and scan matching"};
  app.require_subcommand(1);
  const std::vector<Subcommand> subcommands = {AddInfo(app), AddSimulate(app), AddBuildMap(app), AddMapInfo(app),
                                               AddLocalize(app), AddEvaluate(app), AddRefine(app),
                                               AddOdometry(app), AddMerge(app)};
  int threads = 0;
  app.add_option("--threads", threads, "Worker threads (0: all cores)")->check(NonNegative());
  // info, build-map and localize read a YAML file of their flags with
  // --config (simulate's --config is the world's parameters); flags given on
  // the command line override the file.
  app.set_config("--config", "", "YAML file of the subcommand's flags (info, build-map, localize, odometry)");
  app.config_formatter(std::make_shared<radargauss::YamlConfig>(ConfigSection(argc, argv), ConfigPath(argc, argv)));
  app.allow_config_extras(CLI::config_extras_mode::error);
  for (const Subcommand& command : subcommands) {
    const std::string name = command.app->get_name();
    if (name == "info" || name == "build-map" || name == "localize" || name == "odometry") command.app->fallthrough();
  }
  CheckEveryNumberIsFinite(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ConfigError& e) {
    // CLI11 names the file "INI" and the key section.key.
    const std::string extra = "INI was not able to parse ";
    std::string what = e.what();
    if (what.rfind(extra, 0) == 0) what = "unknown flag '" + what.substr(what.find('.') + 1) + "'";
    std::fprintf(stderr, "radargauss: error: %s: %s\n", ConfigPath(argc, argv).c_str(), what.c_str());
    return 2;
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  std::unique_ptr<tbb::global_control> thread_limit;
  if (threads > 0) {
    thread_limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                         std::size_t(threads));
  }
  try {
    for (const Subcommand& command : subcommands) {
      if (command.app->parsed()) return command.run();
    }
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "radargauss: error: out of memory (an input larger than this machine can hold?)\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "radargauss: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
