// SPDX-License-Identifier: BSD-3-Clause
// RCS normalisation and SH fits (paper section III-A) on planted models.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>

#include "radargauss/core/error.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "support/temp_dir.hpp"
#include "support/map_fixtures.hpp"

namespace radargauss {
namespace {

using testing::RandomUnitVector;

// ---------------------------------------------------------------------------
// RCS models.

std::vector<Eigen::Vector3d> FacingDirections(int n, std::mt19937& rng) {
  std::vector<Eigen::Vector3d> directions;
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d d = RandomUnitVector(rng);
    if (d.x() > 0.0) d = -d;
    directions.push_back(d);
  }
  return directions;
}

TEST(RcsNormalisationTest, EdgeCases) {
  RcsNormalisation n = NormaliseRcs({3.0, 3.0, 3.0});
  EXPECT_FALSE(n.valid);  // all equal: scale 0
  n = NormaliseRcs({1.0, 1.0, 1.0, 5.0});
  EXPECT_FALSE(n.valid);  // median 1 = min: one side empty
  n = NormaliseRcs({0.0, 2.0});
  ASSERT_TRUE(n.valid);  // two points: median 1, scale 1, y = -1 and +1
  EXPECT_EQ(n.median, 1.0);
  EXPECT_EQ(n.scale, 1.0);
  EXPECT_FALSE(NormaliseRcs({4.0}).valid);
  n = NormaliseRcs({-10.0, 0.0, 1.0, 2.0, 30.0});
  EXPECT_EQ(n.median, 1.0);
  EXPECT_EQ(n.scale, 11.0);  // min(1 - -10, 30 - 1)
}

TEST(RcsModelFit, TwoPointsGiveADegreeZeroModelOrNone) {
  const std::vector<Eigen::Vector3d> d = {Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, -1, 0)};
  RcsModel model = FitRcsModel(d, {0.0, 2.0});
  EXPECT_EQ(model.degree, 0);  // lowered from 3: 2 inliers fit 1 coefficient
  EXPECT_EQ(model.inliers, 2u);
  EXPECT_NEAR(model.coefficients[0], 0.0, 1e-12);  // mean of -1 and +1
  RcsFitOptions fixed;
  fixed.adaptive = false;
  EXPECT_FALSE(FitRcsModel(d, {0.0, 2.0}, fixed).valid());
}

// Noise-free normalised RCS from planted SH coefficients is fitted back to
// 1e-9. The normalisation is an affine map of the planted values, so the
// fitted coefficients are c' = (c - med e_0 / C0) / s.
TEST(RcsModelFit, RecoversPlantedCoefficientsExactly) {
  std::mt19937 rng(21);
  std::normal_distribution<double> normal(0.0, 0.3);
  for (int degree = 0; degree <= kMaxShDegree; ++degree) {
    std::array<double, 16> planted{};
    for (int j = 0; j < ShCoefficientCount(degree); ++j) planted[j] = normal(rng);
    const std::vector<Eigen::Vector3d> directions = FacingDirections(80, rng);
    std::vector<double> rcs;
    for (const Eigen::Vector3d& d : directions) rcs.push_back(5.0 + 4.0 * EvaluateSh(degree, planted.data(), d));
    RcsFitOptions options;
    options.max_degree = degree;
    const RcsModel model = FitRcsModel(directions, rcs, options);
    if (degree == 0) {
      EXPECT_FALSE(model.valid());  // a constant RCS has scale 0: no model, as documented
      continue;
    }
    ASSERT_EQ(model.degree, degree);
    EXPECT_LT(model.fit_rmse, 1e-9);
    for (int j = 0; j < ShCoefficientCount(degree); ++j) {
      const double expected =
          (4.0 * planted[j] + (j == 0 ? (5.0 - model.median) / sh_constants::kC0 : 0.0)) / model.scale;
      EXPECT_NEAR(model.coefficients[j], expected, 1e-9) << "degree " << degree << " j " << j;
    }
    // Predictions equal the normalised measurements of the inliers.
    for (std::size_t i = 0; i < rcs.size(); ++i) {
      const double y = model.Normalise(rcs[i]);
      if (std::abs(y) <= 1.0) {
        EXPECT_NEAR(EvaluateSh(model.degree, model.coefficients.data(), directions[i]), y, 1e-9);
      }
    }
  }
}

TEST(RcsModelFit, RmseMatchesNoiseLevel) {
  std::mt19937 rng(22);
  std::normal_distribution<double> coefficient(0.0, 0.3);
  const double noise = 0.5;  // dB
  std::normal_distribution<double> measurement(0.0, noise);
  std::array<double, 16> planted{};
  for (double& c : planted) c = coefficient(rng);
  const std::vector<Eigen::Vector3d> directions = FacingDirections(4000, rng);
  std::vector<double> rcs;
  for (const Eigen::Vector3d& d : directions) {
    rcs.push_back(10.0 * EvaluateSh<3>(planted.data(), d) + measurement(rng));
  }
  const RcsModel model = FitRcsModel(directions, rcs);
  ASSERT_EQ(model.degree, 3);
  EXPECT_NEAR(model.fit_rmse * model.scale, noise, 0.1 * noise);
}

// The fit's statistics (docs/design/map.md, "RCS confidence") on planted data:
// a view law with 1 dB of noise gives a 1 dB spread and a view that explains
// most of the variance; noise alone explains nothing and, with
// min_explained, gets the constant model; a law without noise has no spread
// and no offset to its linear mean.
TEST(RcsModelFit, StatisticsOfPlantedFits) {
  std::mt19937 rng(23);
  std::normal_distribution<double> coefficient(0.0, 0.3), noise(0.0, 1.0);
  std::array<double, 16> planted{};
  for (double& c : planted) c = coefficient(rng);
  const std::vector<Eigen::Vector3d> directions = FacingDirections(3000, rng);
  std::vector<double> law, noisy, pure_noise;
  for (const Eigen::Vector3d& d : directions) {
    law.push_back(10.0 + 10.0 * EvaluateSh<3>(planted.data(), d));
    noisy.push_back(law.back() + noise(rng));
    pure_noise.push_back(10.0 + noise(rng));
  }
  const RcsModel exact = FitRcsModel(directions, law);
  ASSERT_EQ(exact.degree, 3);
  EXPECT_LT(exact.spread_db, 1e-9);
  EXPECT_NEAR(exact.explained, 1.0, 1e-12);
  EXPECT_NEAR(exact.mean_offset_db, 0.0, 1e-9);
  const RcsModel fitted = FitRcsModel(directions, noisy);
  ASSERT_EQ(fitted.degree, 3);
  EXPECT_NEAR(fitted.spread_db, 1.0, 0.08);
  EXPECT_GT(fitted.explained, 0.8);
  // Gaussian dB noise of 1 dB: a linear mean sigma^2 ln(10) / 20 = 0.115 dB above.
  EXPECT_NEAR(fitted.mean_offset_db, std::log(10.0) / 20.0, 0.03);
  const RcsModel noise_only = FitRcsModel(directions, pure_noise);
  EXPECT_LT(noise_only.explained, 0.02);
  RcsFitOptions constant_below;
  constant_below.min_explained = 0.1;
  EXPECT_EQ(FitRcsModel(directions, pure_noise, constant_below).degree, 0);
  EXPECT_EQ(FitRcsModel(directions, noisy, constant_below).degree, 3);
}

TEST(RcsModelFit, CoplanarDirectionsLowerTheDegree) {
  // Directions on one great circle span only 2L + 1 of the (L + 1)^2 functions.
  std::vector<Eigen::Vector3d> directions;
  std::vector<double> rcs;
  for (int i = 0; i < 50; ++i) {
    const double a = M_PI / 2 + M_PI * i / 49.0;
    directions.emplace_back(std::cos(a), std::sin(a), 0.0);
    rcs.push_back(std::sin(3 * a) + 0.1 * i);
  }
  const RcsModel model = FitRcsModel(directions, rcs);
  EXPECT_TRUE(model.valid());
  EXPECT_LT(model.degree, 3);
}

// On a simulated sequence: the share of Gaussians with a model and the mean
// fit RMSE per incidence model (figures for the closing note).
TEST(RcsModelFit, SimulatedSequenceCoverage) {
  SimulationConfig config;
  config.scans = 150;
  const SimulatedSequence simulated = Simulate(config);
  const Sequence sequence = AsSequence(simulated);
  const MapCloud cloud = BuildMapCloud(sequence);
  GaussianMapOptions options;
  GaussianMap map;
  std::vector<int> association;
  map.gaussians = BuildGaussians(cloud.points, options, {}, &association);
  for (const IncidenceModel incidence : {IncidenceModel::kOffset, IncidenceModel::kView}) {
    RcsFitOptions fit;
    fit.incidence = incidence;
    const RcsFitStats stats = FitRcsModels(map, cloud, association, fit);
    const double coverage = double(stats.with_model) / double(stats.gaussians);
    std::printf(
        "incidence %s: %zu Gaussians, %.1f%% with a model (degree 0/1/2/3: %zu/%zu/%zu/%zu), "
        "mean fit RMSE %.4f\n",
        ToString(incidence).c_str(), stats.gaussians, 100.0 * coverage, stats.degree_histogram[0],
        stats.degree_histogram[1], stats.degree_histogram[2], stats.degree_histogram[3], stats.mean_fit_rmse);
    EXPECT_GT(coverage, 0.7);
    EXPECT_GT(stats.mean_fit_rmse, 0.0);
    EXPECT_LT(stats.mean_fit_rmse, 0.7);
    EXPECT_EQ(stats.with_model + stats.no_model, stats.gaussians);
  }
}

// How a target's RCS varies across frames (RcsFitStats), by hand: two
// Gaussians of four members, one 10 m ahead with RCS {0, 2, 4, 6} (std
// sqrt(20/3)), one about 37 m out at 20 deg with {1, 1, 1, 5} (std 2); a
// third of three members is too few to count.
TEST(RcsModelFit, MemberSpreadsByRangeAndAzimuthByHand) {
  MapCloud cloud;
  cloud.has_rcs = true;
  cloud.poses = {SE3d()};
  std::vector<int> association;
  const auto add = [&](const Eigen::Vector3d& at, const std::vector<double>& rcs, int gaussian) {
    for (std::size_t k = 0; k < rcs.size(); ++k) {
      cloud.points.push_back(at + 0.05 * Eigen::Vector3d(double(k + 1), double(k % 2), 0.0));  // not at the mean
      cloud.rcs.push_back(rcs[k]);
      cloud.scan.push_back(0);
      association.push_back(gaussian);
    }
  };
  const double azimuth = 20.0 * M_PI / 180.0;
  const Eigen::Vector3d far(35.0 * std::cos(azimuth), 35.0 * std::sin(azimuth), 0.0);
  add(Eigen::Vector3d(10.0, 0.0, 0.0), {0.0, 2.0, 4.0, 6.0}, 0);
  add(far, {1.0, 1.0, 1.0, 5.0}, 1);
  add(Eigen::Vector3d(5.0, -60.0, 0.0), {0.0, 9.0, 3.0}, 2);
  GaussianMap map;
  for (const Eigen::Vector3d& mean : {Eigen::Vector3d(10.0, 0.0, 0.0), far, Eigen::Vector3d(5.0, -60.0, 0.0)}) {
    Gaussian g;
    g.mean = mean;
    map.gaussians.push_back(g);
  }
  const RcsFitStats stats = FitRcsModels(map, cloud, association);
  const double near_std = std::sqrt(20.0 / 3.0);
  EXPECT_NEAR(stats.member_spread, 0.5 * (near_std + 2.0), 1e-12);
  EXPECT_NEAR(stats.member_spread_by_range[0], near_std, 1e-12);
  EXPECT_NEAR(stats.member_spread_by_range[1], 2.0, 1e-12);
  EXPECT_EQ(stats.member_spread_by_range[2], -1.0);
  EXPECT_EQ(stats.member_spread_by_range[3], -1.0);
  EXPECT_NEAR(stats.member_spread_by_azimuth[0], near_std, 1e-12);
  EXPECT_NEAR(stats.member_spread_by_azimuth[1], 2.0, 1e-12);
  EXPECT_EQ(stats.member_spread_by_azimuth[2], -1.0);
}

}  // namespace
}  // namespace radargauss
