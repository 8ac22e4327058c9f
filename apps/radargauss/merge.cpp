// SPDX-License-Identifier: BSD-3-Clause
// radargauss merge: the folders of `localize --shard I/N`, joined into the
// results one run writes (docs/design/experiment.md, "Shards").
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.hpp"
#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/experiment/experiment.hpp"
#include "radargauss/core/read_file.hpp"

namespace radargauss::cli {

namespace {

struct MergeSettings {
  std::vector<std::string> shards;
  std::string out;
};

int RunMerge(const MergeSettings& s) {
  std::vector<SE3d> references;
  const std::vector<ConfigurationRun> runs = MergeShards(s.shards, references);
  StagedFolder folder(s.out);
  const std::string table = WriteExperimentResults(folder.path(), runs);
  std::vector<double> times;
  for (const ScanOutcome& o : runs.front().outcomes) times.push_back(o.time);
  WriteReferenceTrajectory(folder.path(), times, references);
  // The map's means are the same in every shard (copied through a temporary, as every output).
  namespace fs = std::filesystem;
  const fs::path means = fs::path(s.shards.front()) / "map_means.csv";
  if (fs::exists(means)) {
    const std::string bytes = ReadFileBytes(means.string(), "map means file");
    WriteFileAtomically((fs::path(folder.path()) / "map_means.csv").string(), [&](std::ostream& out) { out << bytes; });
  }
  folder.Commit();
  std::printf("%zu shards, %zu scans, %zu configurations\n\n%s\nresults: %s\n", s.shards.size(), references.size(),
              runs.size(), table.c_str(), s.out.c_str());
  return 0;
}

}  // namespace

Subcommand AddMerge(CLI::App& parent) {
  auto s = std::make_shared<MergeSettings>();
  CLI::App* app = parent.add_subcommand("merge", "Joins the results of localize --shard I/N into one run's");
  app->add_option("shards", s->shards, "The N folders of localize --shard 1/N ... N/N, any order")->required();
  app->add_option("--out", s->out, "Results folder")->required();
  return {app, [s] { return RunMerge(*s); }};
}

}  // namespace radargauss::cli
