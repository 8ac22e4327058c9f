// SPDX-License-Identifier: BSD-3-Clause
// radargauss map-info: summarise a map file.
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/map_tiles.hpp"
#include "radargauss/residuals/rcs_likelihood.hpp"

namespace radargauss::cli {

namespace {

int RunMapInfo(const std::string& path) {
  const GaussianMap map = ReadMapOrTiles(path);
  std::array<std::size_t, kMaxShDegree + 1> histogram{};
  std::size_t with_model = 0, members = 0;
  double rmse = 0.0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY);
  Eigen::Vector3d hi = -lo;
  for (const Gaussian& g : map.gaussians) {
    members += g.point_count;
    lo = lo.cwiseMin(g.mean);
    hi = hi.cwiseMax(g.mean);
    if (g.rcs.valid()) {
      ++with_model;
      ++histogram[g.rcs.degree];
      rmse += g.rcs.fit_rmse;
    }
  }
  const std::size_t n = map.gaussians.size();
  std::printf("map: %s\n", path.c_str());
  std::printf("gaussians: %zu, member points: %zu\n", n, members);
  std::printf("places (SLAM keyframes for relocalize): %zu\n", map.places.size());
  std::printf("incidence model: %s\n", ToString(map.incidence).c_str());
  std::printf("rcs coverage: %zu of %zu (%.1f%%) have a model\n", with_model, n,
              n ? 100.0 * double(with_model) / double(n) : 0.0);
  std::printf("sh degree histogram: none %zu", n - with_model);
  for (int d = 0; d <= kMaxShDegree; ++d) std::printf(", %d: %zu", d, histogram[d]);
  std::printf("\nmean fit RMSE (normalised): %.4f\n", with_model ? rmse / double(with_model) : 0.0);
  for (const RcsLikelihood likelihood : {RcsLikelihood::kDecibel, RcsLikelihood::kSwerling1}) {
    RcsTermOptions options;
    options.likelihood = likelihood;
    const RcsMapSummary rcs = SummariseRcs(map, options);
    if (likelihood == RcsLikelihood::kDecibel) {
      std::printf("rcs fits: median spread %.2f dB, median explained share %.3f\n", rcs.median_spread_db,
                  rcs.median_explained);
    }
    std::printf("rcs confidence (%s): mean %.3f, view information %.3f, chosen w_rcs %.3f\n",
                ToString(likelihood).c_str(), rcs.mean_confidence, rcs.view_information, RcsWeightFromMap(rcs));
  }
  if (n) {
    std::printf("extent: x %.2f..%.2f, y %.2f..%.2f, z %.2f..%.2f m\n", lo.x(), hi.x(), lo.y(), hi.y(), lo.z(), hi.z());
  }
  return 0;
}

}  // namespace

Subcommand AddMapInfo(CLI::App& parent) {
  auto path = std::make_shared<std::string>();
  CLI::App* app = parent.add_subcommand("map-info", "Summarise a map file");
  app->add_option("map", *path, "Map file (.rgm)")->required();
  return {app, [path] { return RunMapInfo(*path); }};
}

}  // namespace radargauss::cli
