// SPDX-License-Identifier: BSD-3-Clause
// The incremental map's statistics against the batch sums of the same members
// (planted points far from the origin, RCS on planted directions), the
// KL divergence against hand-computed cases, and the incremental local map
// against the refit one on a static scene.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "radargauss/map/gaussian_statistics.hpp"
#include "radargauss/odometry/local_map.hpp"

namespace radargauss {
namespace {

double RelativeError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(b.norm(), 1e-300);
}

std::vector<Eigen::Vector3d> PlantedPoints(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  const Eigen::Vector3d far(3.0e3, -2.0e3, 40.0);  // a large offset tests the cancellation
  for (std::size_t k = 0; k < n; ++k)
    points.push_back(far + Eigen::Vector3d(2.0 * normal(rng), 0.5 * normal(rng), 0.1 * normal(rng)));
  return points;
}

// Two passes over the members: the batch reference.
void BatchMoments(const std::vector<Eigen::Vector3d>& points, Eigen::Vector3d& mean, Eigen::Matrix3d& scatter) {
  mean.setZero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= double(points.size());
  scatter.setZero();
  for (const Eigen::Vector3d& p : points) scatter += (p - mean) * (p - mean).transpose();
}

TEST(PointStatistics, AddRemoveAndMergeEqualTheBatchMoments) {
  const std::vector<Eigen::Vector3d> points = PlantedPoints(400, 1);
  PointStatistics added, first, second;
  for (const Eigen::Vector3d& p : points) added.Add(p);
  for (std::size_t k = 0; k < points.size(); ++k) (k < 150 ? first : second).Add(points[k]);
  PointStatistics merged = first;
  merged.Merge(second);
  Eigen::Vector3d mean;
  Eigen::Matrix3d scatter;
  BatchMoments(points, mean, scatter);
  for (const PointStatistics* s : {&added, &merged}) {
    EXPECT_EQ(s->count, points.size());
    EXPECT_LT(RelativeError(s->mean, mean), 1e-12);
    EXPECT_LT(RelativeError(s->scatter, scatter), 1e-9);
    EXPECT_LT(RelativeError(s->Covariance(), scatter / double(points.size())), 1e-9);
  }
  // Removing every third point leaves the others' moments.
  std::vector<Eigen::Vector3d> kept;
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (k % 3 == 0) {
      added.Remove(points[k]);
    } else {
      kept.push_back(points[k]);
    }
  }
  BatchMoments(kept, mean, scatter);
  EXPECT_EQ(added.count, kept.size());
  EXPECT_LT(RelativeError(added.mean, mean), 1e-12);
  EXPECT_LT(RelativeError(added.scatter, scatter), 1e-9);
  added.Remove(kept[0]);
  for (std::size_t k = 1; k < kept.size(); ++k) added.Remove(kept[k]);
  EXPECT_EQ(added.count, 0u);
  EXPECT_EQ(added.scatter, Eigen::Matrix3d::Zero());
}

struct PlantedRcs {
  std::vector<Eigen::Vector3d> directions;
  std::vector<double> rcs;
};

// Directions over the front half-sphere, RCS a degree-3 pattern plus noise
// and a few wild values the normalisation rejects.
PlantedRcs PlantRcs(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  PlantedRcs planted;
  for (std::size_t k = 0; k < n; ++k) {
    Eigen::Vector3d d(-std::abs(normal(rng)), normal(rng), 0.5 * normal(rng));
    d.normalize();
    double basis[RcsStatistics::kSize];
    EvaluateShBasis<kMaxShDegree>(d, basis);
    double value = 5.0 + 0.3 * normal(rng);
    for (int j = 0; j < RcsStatistics::kSize; ++j) value += std::sin(1.0 + j) * basis[j];
    if (k % 17 == 0) value += 30.0;
    planted.directions.push_back(d);
    planted.rcs.push_back(value);
  }
  return planted;
}

TEST(RcsStatistics, NormalEquationsEqualTheBatchSumsAndSolveAsFitRcsModel) {
  const PlantedRcs planted = PlantRcs(300, 2);
  RcsStatistics stats(NormaliseRcs(planted.rcs));
  ASSERT_TRUE(stats.normalisation.valid);
  for (std::size_t k = 0; k < planted.rcs.size(); ++k) stats.Add(planted.directions[k], planted.rcs[k]);
  for (std::size_t k = 0; k < planted.rcs.size(); k += 4) stats.Remove(planted.directions[k], planted.rcs[k]);
  // The batch system over the inliers that stay: A^T A, A^T y, |y|^2.
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(RcsStatistics::kSize, RcsStatistics::kSize);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(RcsStatistics::kSize);
  std::size_t inliers = 0;
  std::vector<Eigen::Vector3d> kept_directions;
  std::vector<double> kept_rcs;
  for (std::size_t k = 0; k < planted.rcs.size(); ++k) {
    if (k % 4 == 0 || !stats.IsInlier(planted.rcs[k])) continue;
    Eigen::VectorXd basis(RcsStatistics::kSize);
    EvaluateShBasis<kMaxShDegree>(planted.directions[k], basis.data());
    const double y = (planted.rcs[k] - stats.normalisation.median) / stats.normalisation.scale;
    normal += basis * basis.transpose();
    rhs += y * basis;
    ++inliers;
  }
  const Eigen::MatrixXd incremental = stats.normal.selfadjointView<Eigen::Lower>();
  EXPECT_EQ(stats.inliers, inliers);
  EXPECT_LT(RelativeError(incremental, normal), 1e-9);
  EXPECT_LT(RelativeError(stats.rhs, rhs), 1e-9);
  // All members under one normalisation: the same model as the batch fit.
  RcsStatistics all(NormaliseRcs(planted.rcs));
  for (std::size_t k = 0; k < planted.rcs.size(); ++k) all.Add(planted.directions[k], planted.rcs[k]);
  const RcsModel expected = FitRcsModel(planted.directions, planted.rcs);
  const RcsModel model = all.Solve(RcsFitOptions());
  ASSERT_EQ(model.degree, expected.degree);
  EXPECT_EQ(model.inliers, expected.inliers);
  EXPECT_EQ(model.median, expected.median);
  EXPECT_EQ(model.scale, expected.scale);
  for (int j = 0; j < RcsStatistics::kSize; ++j)
    EXPECT_NEAR(model.coefficients[j], expected.coefficients[j], 1e-8) << j;
  EXPECT_NEAR(model.fit_rmse, expected.fit_rmse, 1e-9);
  EXPECT_NEAR(model.spread_db, expected.spread_db, 1e-8);
  EXPECT_NEAR(model.explained, expected.explained, 1e-9);
}

TEST(KullbackLeibler, HandComputedCases) {
  const Eigen::Matrix3d sigma = Eigen::Vector3d(0.04, 0.09, 0.01).asDiagonal();
  const Eigen::Vector3d mu(1.0, 2.0, 3.0);
  EXPECT_NEAR(KullbackLeibler(mu, sigma, mu, sigma), 0.0, 1e-12);
  // Same covariance: half the Mahalanobis^2 of the shift, 0.5 (0.2^2 / 0.04) = 0.5.
  EXPECT_NEAR(KullbackLeibler(mu + Eigen::Vector3d(0.2, 0.0, 0.0), sigma, mu, sigma), 0.5, 1e-12);
  // Covariance scaled by s: (3 s - 3 - 3 ln s) / 2.
  const double s = 1.5;
  EXPECT_NEAR(KullbackLeibler(mu, s * sigma, mu, sigma), 0.5 * (3.0 * s - 3.0 - 3.0 * std::log(s)), 1e-12);
}

// A static scene: three walls and a pole sampled anew in each of 12 scans.
std::vector<std::vector<Eigen::Vector3d>> StaticScene() {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> along(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.03);
  std::vector<std::vector<Eigen::Vector3d>> scans(12);
  for (auto& scan : scans) {
    for (int k = 0; k < 300; ++k) {
      const double u = along(rng), v = along(rng);
      switch (k % 4) {
        case 0:
          scan.emplace_back(12.0 * u, 6.0 + noise(rng), 3.0 * v);
          break;
        case 1:
          scan.emplace_back(12.0 * u, -6.0 + noise(rng), 3.0 * v);
          break;
        case 2:
          scan.emplace_back(12.0 + noise(rng), -6.0 + 12.0 * u, 3.0 * v);
          break;
        default:
          scan.emplace_back(5.0 + noise(rng), 1.0 + noise(rng), 3.0 * v);
          break;
      }
    }
  }
  return scans;
}

// How far a point is from the planted scene: the walls y = +-6 m and x = 12 m,
// the pole's axis at (5, 1).
double DistanceFromScene(const Eigen::Vector3d& p) {
  return std::min(
      {std::abs(p.y() - 6.0), std::abs(p.y() + 6.0), std::abs(p.x() - 12.0), std::hypot(p.x() - 5.0, p.y() - 1.0)});
}

struct MapSummary {
  std::size_t associated = 0;  // of the last scan's points, within 3 sigma of a Gaussian
  double median_d2 = 0.0;      // their Mahalanobis^2
  double median_std = 0.0;     // the Gaussians' largest principal std
  double median_offset = 0.0;  // the Gaussians' means from the planted scene
};

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

MapSummary Summarise(const std::vector<Gaussian>& gaussians, const std::vector<Eigen::Vector3d>& scan) {
  const GaussianIndex index(gaussians, 1.0);
  std::vector<double> d2, stds, offsets;
  for (const Eigen::Vector3d& p : scan) {
    double m = 0.0;
    if (index.Associate(p, 9.0, &m) >= 0) d2.push_back(m);
  }
  for (const Gaussian& g : gaussians) {
    Eigen::Vector3d std_devs;
    Eigen::Matrix3d axes;
    PrincipalAxes(g.covariance, std_devs, axes);
    stds.push_back(std_devs[2]);
    offsets.push_back(DistanceFromScene(g.mean));
  }
  return {d2.size(), Median(d2), Median(stds), Median(offsets)};
}

// The bound the two estimators agree within on a static scene (docs/design/odometry.md,
// "The incremental map"): Gaussian count within 20 %; as many of a scan's
// points within the gate, as close in Mahalanobis terms (median within 30 %);
// the median largest std within 30 %; the means on the planted surfaces
// (median within 5 cm of them).
TEST(IncrementalMap, AgreesWithTheRefitMapOnAStaticScene) {
  const std::vector<std::vector<Eigen::Vector3d>> scans = StaticScene();
  LocalMapOptions options;
  options.gaussians.points_per_gaussian = 8.0;
  const auto build = [&](MapEstimator estimator) {
    options.estimator = estimator;
    LocalMap map(options);
    for (const auto& scan : scans) map.Insert(scan, {}, SE3d(SO3d(), Eigen::Vector3d(6.0, 0.0, 1.0)));
    return map.GlobalMap().gaussians;
  };
  const std::vector<Gaussian> refit = build(MapEstimator::kRefit);
  const std::vector<Gaussian> incremental = build(MapEstimator::kIncremental);
  ASSERT_GT(refit.size(), 20u);
  EXPECT_NEAR(double(incremental.size()) / double(refit.size()), 1.0, 0.2);
  const MapSummary a = Summarise(refit, scans.back()), b = Summarise(incremental, scans.back());
  EXPECT_GT(double(b.associated), 0.9 * double(a.associated));
  EXPECT_NEAR(b.median_d2 / a.median_d2, 1.0, 0.3);
  EXPECT_NEAR(b.median_std / a.median_std, 1.0, 0.3);
  EXPECT_LT(a.median_offset, 0.05);
  EXPECT_LT(b.median_offset, 0.05);
}

}  // namespace
}  // namespace radargauss
