// SPDX-License-Identifier: BSD-3-Clause
// radargauss build-map: the Gaussian-RCS map of a sequence, as a map file.
#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/map/map_file.hpp"

namespace radargauss::cli {

namespace {

struct BuildMapSettings {
  SequenceOptions sequence;
  MapBuildSettings build;
  std::string out;
  std::string ply;
};

int RunBuildMap(const BuildMapSettings& s) {
  if (s.sequence.ground_truth.empty()) throw DataError("build-map needs --gt");
  const Sequence sequence = LoadSequence(s.sequence);
  const MapGeometry geometry = BuildGeometry(sequence, s.build, true);
  const GaussianMap map =
      FitRcsModelsOf(geometry, s.build, s.build.map.rcs.incidence, s.build.map.rcs.max_degree, true);
  WriteMap(s.out, map);
  if (!s.ply.empty()) ExportPly(s.ply, map);
  std::printf("wrote %s%s%s\n", s.out.c_str(), s.ply.empty() ? "" : " and ", s.ply.c_str());
  return 0;
}

}  // namespace

Subcommand AddBuildMap(CLI::App& parent) {
  auto s = std::make_shared<BuildMapSettings>();
  CLI::App* app = parent.add_subcommand("build-map", "Build a Gaussian-RCS map of a sequence");
  AddSequenceOptions(app, s->sequence);
  AddMapBuildOptions(app, s->build);
  app->add_option("--out", s->out, "Map file (.rgm)")->required();
  app->add_option("--ply", s->ply, "Also export a 3DGS-layout PLY");
  return {app, [s] { return RunBuildMap(*s); }};
}

}  // namespace radargauss::cli
