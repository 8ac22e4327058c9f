// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/experiment/experiment.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <sstream>

#include "radargauss/radargauss.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "radargauss/core/trajectory.hpp"
#include "radargauss/solvers/gauss_newton.hpp"
#include "support/temp_dir.hpp"

namespace radargauss {
namespace {

using Experiment = testing::TempDirTest;

TEST(ExperimentErrors, SeededAndBounded) {
  const std::vector<SE3d> a = InitialErrors(200, 2.0, 5.0, 7);
  const std::vector<SE3d> b = InitialErrors(200, 2.0, 5.0, 7);
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].Matrix(), b[k].Matrix());
    EXPECT_LE(a[k].translation().norm(), 2.0);
    EXPECT_LE(a[k].rotation().Log().norm(), 5.0 * M_PI / 180.0 + 1e-12);
  }
  const ErrorStatistics s = Statistics({1.0, 2.0, 3.0, 10.0});
  EXPECT_EQ(s.mean, 4.0);
  EXPECT_EQ(s.median, 2.5);
  EXPECT_EQ(s.max, 10.0);
  EXPECT_NEAR(s.rmse, std::sqrt(114.0 / 4.0), 1e-12);
}

// A short simulated sequence end to end: outputs exist and parse, and the
// errors at w = 0 are below the initial ones.
TEST_F(Experiment, ShortSequenceEndToEnd) {
  SimulationConfig config;
  config.scans = 30;
  config.seed = 9;
  const SimulatedSequence simulated = Simulate(config);
  const Sequence sequence = AsSequence(simulated);
  const MatchingMap matching(BuildMap(sequence));
  const std::vector<SE3d> errors = InitialErrors(sequence.scans.size(), 2.0, 5.0, 42);
  std::vector<ConfigurationRun> runs;
  for (const double w : {0.0, 0.25}) {
    ScanMatchingOptions options;
    options.w_rcs = w;
    runs.push_back(RunConfiguration("gn-w" + std::to_string(w), w, GaussNewtonSolver(options), matching, sequence.scans,
                                    sequence.poses, errors));
  }
  const std::string table = WriteExperimentResults(dir_.string(), runs);
  EXPECT_NE(table.find("**"), std::string::npos);  // a best value is marked

  std::ifstream json_file(Path("summary.json"));
  const nlohmann::json summary = nlohmann::json::parse(json_file);
  ASSERT_EQ(summary.size(), 2u);
  EXPECT_EQ(summary[0]["scans"], 30);
  double initial = 0.0;
  for (const ScanOutcome& o : runs[0].outcomes) initial += o.initial_translation_error / 30.0;
  const double final_mean = summary[0]["translation_m"]["mean"];
  EXPECT_LT(final_mean, initial);
  EXPECT_LT(double(summary[0]["translation_m"]["median"]), 0.1);

  std::ifstream csv(Path("per_scan.csv"));
  std::string line;
  std::size_t rows = 0;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("scan,time,configuration,w_rcs", 0), 0u);
  while (std::getline(csv, line)) {
    std::stringstream fields(line);
    std::string field;
    int count = 0;
    while (std::getline(fields, field, ',')) ++count;
    EXPECT_EQ(count, 14) << line;
    ++rows;
  }
  EXPECT_EQ(rows, 60u);
  EXPECT_EQ(ReadTum(Path("trajectories/" + runs[0].name + ".tum")).size(), 30u);
}

}  // namespace
}  // namespace radargauss
