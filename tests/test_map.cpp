#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>

#include "radargauss/error.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/simulator.hpp"
#include "temp_dir.hpp"
#include "test_util.hpp"

namespace radargauss {
namespace {

using testing::RandomUnitVector;
using MapFiles = testing::TempDirTest;

struct Planted {
  std::vector<Gaussian> gaussians;
  std::vector<Eigen::Vector3d> points;
};

// Well-separated anisotropic Gaussians on a 6 m grid, `per` samples each.
Planted PlantGaussians(int per, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.15, 0.45);
  Planted planted;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      Gaussian g;
      g.mean = Eigen::Vector3d(6.0 * i, 6.0 * j, 1.0 + 0.5 * i);
      const Eigen::Matrix3d axes = SO3d::Exp(RandomUnitVector(rng)).Matrix();
      const Eigen::Vector3d stds(uniform(rng), uniform(rng), uniform(rng));
      g.covariance = ClampCovariance(axes * stds.array().square().matrix().asDiagonal() * axes.transpose(),
                                     0.0);
      const Eigen::Matrix3d root = axes * stds.asDiagonal();
      for (int k = 0; k < per; ++k) {
        planted.points.push_back(g.mean + root * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
      }
      planted.gaussians.push_back(g);
    }
  }
  return planted;
}

// Voxel downsampling: the centroid of each occupied voxel (by hand), in key
// order or in the order of each voxel's first point, non-finite points
// skipped; many random clouds give the same centroids in both orders.
TEST(VoxelDownsample, CentroidsPerVoxelInEitherOrder) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Eigen::Vector3d> points = {
      {1.2, 0.1, 0.1}, {-0.5, 0.5, 0.5}, {1.6, 0.3, 0.9}, {nan, 0.0, 0.0}, {-0.7, 0.1, 0.3}, {0.5, 0.5, 0.5}};
  // Voxels of 1 m: (1,0,0) first, then (-1,0,0), then (0,0,0).
  const std::vector<Eigen::Vector3d> by_first = {
      {1.4, 0.2, 0.5}, {-0.6, 0.3, 0.4}, {0.5, 0.5, 0.5}};
  const std::vector<Eigen::Vector3d> first = VoxelDownsample(points, 1.0, VoxelOrder::kFirstPoint);
  const std::vector<Eigen::Vector3d> keyed = VoxelDownsample(points, 1.0);
  ASSERT_EQ(first.size(), 3u);
  ASSERT_EQ(keyed.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_LT((first[k] - by_first[k]).norm(), 1e-12) << k;
  EXPECT_LT((keyed[0] - by_first[1]).norm(), 1e-12);  // x = -1, 0, 1
  EXPECT_LT((keyed[1] - by_first[2]).norm(), 1e-12);
  EXPECT_LT((keyed[2] - by_first[0]).norm(), 1e-12);
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 5.0);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Eigen::Vector3d> cloud(1 + rng() % 3000);
    for (Eigen::Vector3d& p : cloud) p = {normal(rng), normal(rng), 0.2 * normal(rng)};
    const double voxel = 0.1 + 0.2 * trial;
    const auto less = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
      return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
    };
    std::vector<Eigen::Vector3d> a = VoxelDownsample(cloud, voxel, VoxelOrder::kFirstPoint);
    std::vector<Eigen::Vector3d> b = VoxelDownsample(cloud, voxel);
    for (std::size_t k = 1; k < b.size(); ++k) {
      EXPECT_TRUE(VoxelOf(b[k - 1], voxel) < VoxelOf(b[k], voxel)) << "trial " << trial;
    }
    std::sort(a.begin(), a.end(), less);
    std::sort(b.begin(), b.end(), less);
    EXPECT_EQ(a, b) << "trial " << trial;
  }
  EXPECT_TRUE(VoxelDownsample({}, 1.0).empty());
}

TEST(GaussianBuilder, RecoversPlantedGaussians) {
  const Planted planted = PlantGaussians(2000, 1);
  GaussianMapOptions options;
  options.downsample_voxel = 0.02;
  // K from the density, as the method sets it: here so that K = 16.
  const std::size_t downsampled = VoxelDownsample(planted.points, options.downsample_voxel).size();
  options.points_per_gaussian = double(downsampled) / planted.gaussians.size();
  options.em_iterations = 20;
  const std::vector<Gaussian> built = BuildGaussians(planted.points, options);
  ASSERT_EQ(built.size(), planted.gaussians.size());
  for (const Gaussian& p : planted.gaussians) {
    const Gaussian* nearest = &built[0];
    for (const Gaussian& b : built) {
      if ((b.mean - p.mean).norm() < (nearest->mean - p.mean).norm()) nearest = &b;
    }
    EXPECT_LT((nearest->mean - p.mean).norm(), 0.1) << p.mean.transpose();
    EXPECT_LT((nearest->covariance - p.covariance).norm(), 0.15 * p.covariance.norm())
        << "planted\n" << p.covariance << "\nbuilt\n" << nearest->covariance;
    EXPECT_GT(nearest->point_count, 1900u);  // members within tau = 3 of 2000 samples
  }
}

TEST(GaussianBuilder, SameResultForAnyThreadCount) {
  const Planted planted = PlantGaussians(500, 2);
  GaussianMapOptions options;
  std::vector<Gaussian> one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = BuildGaussians(planted.points, options);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = BuildGaussians(planted.points, options);
  }
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].mean, two[i].mean);
    EXPECT_EQ(one[i].covariance, two[i].covariance);
    EXPECT_EQ(one[i].point_count, two[i].point_count);
  }
}

TEST(GaussianBuilder, ClampsStdAndVoxelBaseline) {
  // Points on a plane: the normal std is clamped to min_std.
  std::vector<Eigen::Vector3d> plane;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) plane.emplace_back(0.05 * i, 0.05 * j, 0.0);
  }
  GaussianMapOptions options;
  options.builder = MapBuilder::kVoxel;
  options.ndt_voxel = 1.0;
  const std::vector<Gaussian> voxel = BuildGaussians(plane, options);
  ASSERT_EQ(voxel.size(), 4u);  // 2 m x 2 m of plane in 1 m voxels
  for (const Gaussian& g : voxel) {
    Eigen::Vector3d stds;
    Eigen::Matrix3d axes;
    PrincipalAxes(g.covariance, stds, axes);
    EXPECT_NEAR(stds[0], options.min_std, 1e-12);
    EXPECT_EQ(g.point_count, 400u);
  }
  EXPECT_THROW(BuildGaussians({}, options), std::invalid_argument);
  options.min_std = 0.0;
  EXPECT_THROW(BuildGaussians(plane, options), std::invalid_argument);
}

// The index gives the brute-force answer: every point within tau <= 3 of a
// Gaussian lies in a cell its 3-sigma ellipsoid meets. So does the batched
// query (AssociateAll), which fetches ahead and must not change an answer.
TEST(GaussianIndexTest, MatchesBruteForceAssociation) {
  const Planted planted = PlantGaussians(10, 3);
  const GaussianIndex index(planted.gaussians, 0.7);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> uniform(-2.0, 20.0);
  int associated = 0;
  std::vector<Eigen::Vector3d> points;
  std::vector<int> expected_all;
  std::vector<double> expected_d2;
  for (int trial = 0; trial < 20000; ++trial) {
    const Eigen::Vector3d p(uniform(rng), uniform(rng), 0.2 * uniform(rng));
    int expected = -1;
    double best = 9.0;
    for (std::size_t g = 0; g < planted.gaussians.size(); ++g) {
      const Eigen::Vector3d e = p - planted.gaussians[g].mean;
      const double d2 = e.dot(planted.gaussians[g].covariance.inverse() * e);
      if (d2 <= best) {
        best = d2;
        expected = int(g);
      }
    }
    points.push_back(p);
    expected_all.push_back(expected);
    expected_d2.push_back(best);
    double d2 = 0.0;
    ASSERT_EQ(index.Associate(p, 9.0, &d2), expected) << p.transpose();
    if (expected >= 0) {
      EXPECT_NEAR(d2, best, 1e-9);
      ++associated;
      // ||L^T e||^2 is the Mahalanobis^2 too, and so is MahalanobisSq.
      EXPECT_NEAR((index.SqrtInformationT(expected) * (p - index.Mean(expected))).squaredNorm(), best,
                  1e-9);
      EXPECT_NEAR(index.MahalanobisSq(expected, p - index.Mean(expected)), best, 1e-9);
    }
  }
  EXPECT_GT(associated, 50);
  // The information the index forms from its factor L^T is Sigma^-1.
  for (std::size_t g = 0; g < planted.gaussians.size(); ++g) {
    const Eigen::Matrix3d information = planted.gaussians[g].covariance.inverse();
    EXPECT_LT((index.Information(g) - information).norm(), 1e-10 * information.norm()) << g;
  }
  std::vector<int> batched(points.size(), -2);
  std::vector<double> batched_d2(points.size(), -1.0);
  index.AssociateAll(points.data(), points.size(), 9.0, batched.data(), batched_d2.data());
  EXPECT_EQ(batched, expected_all);
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (expected_all[k] >= 0) {
      ASSERT_NEAR(batched_d2[k], expected_d2[k], 1e-9) << k;
    }
  }
  // A non-finite point has no association, and the points around it keep theirs.
  const Eigen::Vector3d nan_point(std::nan(""), 1.0, 0.0);
  const Eigen::Vector3d inf_point(1.0, std::numeric_limits<double>::infinity(), 0.0);
  EXPECT_EQ(index.Associate(nan_point, 9.0), -1);
  EXPECT_EQ(index.Associate(inf_point, 9.0), -1);
  std::vector<Eigen::Vector3d> with_bad(points.begin(), points.begin() + 40);
  with_bad[10] = nan_point;
  with_bad[20] = inf_point;
  std::vector<int> with_bad_out(with_bad.size(), -2);
  index.AssociateAll(with_bad.data(), with_bad.size(), 9.0, with_bad_out.data());
  for (std::size_t k = 0; k < with_bad.size(); ++k) {
    EXPECT_EQ(with_bad_out[k], k == 10 || k == 20 ? -1 : expected_all[k]) << k;
  }
  // Fewer points than the batch looks ahead.
  index.AssociateAll(points.data(), 3, 9.0, batched.data());
  EXPECT_EQ(std::vector<int>(batched.begin(), batched.begin() + 3),
            std::vector<int>(expected_all.begin(), expected_all.begin() + 3));
}

// The smallest Mahalanobis^2 from `mean` over the box [lo, hi], exactly: the
// minimum of a convex quadratic over a box is where some coordinates lie on
// a face and the others minimise it given them; the least of those points
// that are in the box (27 face choices).
double SmallestMahalanobisSqOverBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                    const Eigen::Vector3d& mean, const Eigen::Matrix3d& information) {
  double smallest = std::numeric_limits<double>::infinity();
  for (int choice = 0; choice < 27; ++choice) {
    int face[3];  // 0: free, 1: on lo, 2: on hi
    std::vector<int> free;
    Eigen::Vector3d x = mean;
    for (int i = 0, c = choice; i < 3; ++i, c /= 3) {
      face[i] = c % 3;
      if (face[i] == 0) free.push_back(i);
      if (face[i] == 1) x[i] = lo[i];
      if (face[i] == 2) x[i] = hi[i];
    }
    if (!free.empty()) {  // d/dx_f of (x - mu)^T I (x - mu) = 0 for the free coordinates
      const int n = int(free.size());
      Eigen::MatrixXd A(n, n);
      Eigen::VectorXd b(n);
      for (int r = 0; r < n; ++r) {
        b[r] = 0.0;
        for (int i = 0; i < 3; ++i) {
          if (face[i] != 0) b[r] -= information(free[r], i) * (x[i] - mean[i]);
        }
        for (int c = 0; c < n; ++c) A(r, c) = information(free[r], free[c]);
      }
      const Eigen::VectorXd offset = A.ldlt().solve(b);
      bool inside = true;
      for (int r = 0; r < n; ++r) {
        x[free[r]] = mean[free[r]] + offset[r];
        inside = inside && x[free[r]] >= lo[free[r]] && x[free[r]] <= hi[free[r]];
      }
      if (!inside) continue;
    }
    smallest = std::min(smallest, (x - mean).dot(information * (x - mean)));
  }
  return smallest;
}

// The index lists a Gaussian in exactly the cells its ellipsoid of 3 std
// meets, not in every cell of the ellipsoid's box: against the exact
// smallest Mahalanobis distance over each cell of the box, for a flat
// oblique Gaussian (most of its box is empty) and a round one (the box's
// corners are).
TEST(GaussianIndexTest, ListsAGaussianInTheCellsItsEllipsoidMeets) {
  const double cell = 0.25;
  Gaussian flat;
  flat.mean = Eigen::Vector3d(0.31, -0.22, 0.13);
  const Eigen::Matrix3d axes = SO3d::Exp(Eigen::Vector3d(0.4, 0.7, 0.2)).Matrix();
  flat.covariance = axes * Eigen::Vector3d(1.0, 0.36, 0.0025).asDiagonal() * axes.transpose();
  Gaussian round;
  round.mean = Eigen::Vector3d(-0.07, 0.11, 0.05);
  round.covariance = 0.09 * Eigen::Matrix3d::Identity();
  for (const Gaussian& g : {flat, round}) {
    const GaussianIndex index({g}, cell);
    const Eigen::Matrix3d information = g.covariance.inverse();
    const Eigen::Vector3d half = 3.0 * g.covariance.diagonal().cwiseSqrt();
    const VoxelKey lo = VoxelOf(g.mean - half, cell), hi = VoxelOf(g.mean + half, cell);
    int box_cells = 0, listed = 0;
    for (auto x = lo.x; x <= hi.x; ++x) {
      for (auto y = lo.y; y <= hi.y; ++y) {
        for (auto z = lo.z; z <= hi.z; ++z) {
          const Eigen::Vector3d corner = cell * Eigen::Vector3d(double(x), double(y), double(z));
          const double smallest = SmallestMahalanobisSqOverBox(corner, corner.array() + cell, g.mean, information);
          std::size_t count = 0;
          index.Candidates(corner.array() + 0.5 * cell, count);
          ++box_cells;
          listed += int(count);
          // Cells whose distance is within 0.1% of the extent may go either way.
          if (std::abs(smallest - 9.0) > 0.02) {
            EXPECT_EQ(count, smallest < 9.0 ? 1u : 0u) << x << " " << y << " " << z << ": " << smallest;
          }
        }
      }
    }
    EXPECT_LT(listed, 0.8 * box_cells) << listed << " of " << box_cells;
    // Points on the ellipsoid (just inside the gate) find the Gaussian in their cell.
    std::mt19937 rng(7);
    const Eigen::Matrix3d root = g.covariance.llt().matrixL();
    for (int k = 0; k < 5000; ++k) {
      const Eigen::Vector3d p = g.mean + root * (3.0 * (1.0 - 1e-12) * RandomUnitVector(rng));
      ASSERT_EQ(index.Associate(p, 9.0), 0) << p.transpose();
    }
  }
  EXPECT_THROW(GaussianIndex({flat}, cell, 0.0), std::invalid_argument);
}

// A point exactly on the gate is associated, one just beyond it is not, and
// of two equally close Gaussians the one with the smaller id wins (the
// branch-free selection keeps both rules).
TEST(GaussianIndexTest, GateIsInclusiveAndTiesGoToTheSmallestId) {
  Gaussian unit;
  unit.mean.setZero();
  unit.covariance.setIdentity();  // information I: Mahalanobis^2 = |p|^2, exactly
  Gaussian far = unit;
  far.mean = Eigen::Vector3d(10.0, 0.0, 0.0);
  const GaussianIndex index({far, unit, unit}, 0.5);  // ids 1 and 2 coincide
  const std::vector<Eigen::Vector3d> points = {Eigen::Vector3d(3.0, 0.0, 0.0), Eigen::Vector3d(0.0, -3.0, 0.0),
                                               Eigen::Vector3d(0.0, 0.0, 3.0000001),
                                               Eigen::Vector3d(1.0, 2.0, 2.0)};
  const std::vector<int> expected = {1, 1, -1, 1};  // |p|^2 = 9, 9, > 9, 9
  for (std::size_t k = 0; k < points.size(); ++k) {
    double d2 = -1.0;
    EXPECT_EQ(index.Associate(points[k], 9.0, &d2), expected[k]) << k;
    if (expected[k] >= 0) {
      EXPECT_EQ(d2, 9.0) << k;
    }
  }
  std::vector<int> batched(points.size(), -2);
  index.AssociateAll(points.data(), points.size(), 9.0, batched.data());
  EXPECT_EQ(batched, expected);
  // A gate below the distance leaves every point unassociated.
  index.AssociateAll(points.data(), points.size(), 8.99, batched.data());
  EXPECT_EQ(batched, std::vector<int>(points.size(), -1));
}

TEST(GaussianIndexTest, EmptyIndexAssociatesNothing) {
  const Eigen::Vector3d p(0.1, -0.2, 0.3);
  std::size_t count = 1;
  EXPECT_EQ(GaussianIndex().Associate(p, 9.0), -1);
  EXPECT_EQ(GaussianIndex().Candidates(p, count), nullptr);
  EXPECT_EQ(count, 0u);
  EXPECT_EQ(GaussianIndex({}, 0.5).Associate(p, 9.0), -1);
  const std::vector<Eigen::Vector3d> points(20, p);
  std::vector<int> associations(points.size(), 7);
  GaussianIndex().AssociateAll(points.data(), points.size(), 9.0, associations.data());
  EXPECT_EQ(associations, std::vector<int>(points.size(), -1));
  associations.assign(points.size(), 7);
  GaussianIndex({}, 0.5).AssociateAll(points.data(), points.size(), 9.0, associations.data());
  EXPECT_EQ(associations, std::vector<int>(points.size(), -1));
}

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
  ASSERT_TRUE(n.valid);   // two points: median 1, scale 1, y = -1 and +1
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
      const double expected = (4.0 * planted[j] + (j == 0 ? (5.0 - model.median) / sh_constants::kC0 : 0.0)) /
                              model.scale;
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
    std::printf("incidence %s: %zu Gaussians, %.1f%% with a model (degree 0/1/2/3: %zu/%zu/%zu/%zu), "
                "mean fit RMSE %.4f\n",
                ToString(incidence).c_str(), stats.gaussians, 100.0 * coverage,
                stats.degree_histogram[0], stats.degree_histogram[1], stats.degree_histogram[2],
                stats.degree_histogram[3], stats.mean_fit_rmse);
    EXPECT_GT(coverage, 0.7);
    EXPECT_GT(stats.mean_fit_rmse, 0.0);
    EXPECT_LT(stats.mean_fit_rmse, 0.7);
    EXPECT_EQ(stats.with_model + stats.no_model, stats.gaussians);
  }
}

// ---------------------------------------------------------------------------
// Map files.

GaussianMap ExampleMap() {
  const Planted planted = PlantGaussians(1, 5);
  GaussianMap map;
  map.incidence = IncidenceModel::kView;
  map.gaussians = planted.gaussians;
  std::mt19937 rng(6);
  std::normal_distribution<double> normal;
  for (std::size_t i = 0; i < map.gaussians.size(); ++i) {
    Gaussian& g = map.gaussians[i];
    g.point_count = std::uint32_t(10 + i);
    if (i % 3 == 0) continue;  // no model
    g.rcs.degree = int(i % 4);
    g.rcs.median = normal(rng);
    g.rcs.scale = 1.0 + std::abs(normal(rng));
    g.rcs.fit_rmse = 0.1;
    g.rcs.inliers = 9;
    for (int j = 0; j < ShCoefficientCount(g.rcs.degree); ++j) g.rcs.coefficients[j] = normal(rng);
  }
  return map;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

TEST_F(MapFiles, RoundTripIsBitExact) {
  const GaussianMap map = ExampleMap();
  WriteMap(Path("a.rgm"), map);
  const GaussianMap read = ReadMap(Path("a.rgm"));
  EXPECT_EQ(read.incidence, map.incidence);
  ASSERT_EQ(read.gaussians.size(), map.gaussians.size());
  for (std::size_t i = 0; i < map.gaussians.size(); ++i) {
    EXPECT_EQ(read.gaussians[i].mean, map.gaussians[i].mean);
    EXPECT_EQ(read.gaussians[i].covariance, map.gaussians[i].covariance);
    EXPECT_EQ(read.gaussians[i].rcs.coefficients, map.gaussians[i].rcs.coefficients);
    EXPECT_EQ(read.gaussians[i].rcs.degree, map.gaussians[i].rcs.degree);
  }
  WriteMap(Path("b.rgm"), read);
  EXPECT_EQ(ReadBytes(Path("a.rgm")), ReadBytes(Path("b.rgm")));
}

TEST_F(MapFiles, CorruptFilesGiveClearErrors) {
  WriteMap(Path("good.rgm"), ExampleMap());
  const std::string good = ReadBytes(Path("good.rgm"));
  const auto expect_error = [&](const std::string& bytes, const std::string& fault) {
    const std::string path = WriteFile("bad.rgm", bytes);
    try {
      ReadMap(path);
      ADD_FAILURE() << "accepted a map with " << fault;
    } catch (const DataError& e) {
      EXPECT_NE(std::string(e.what()).find(fault), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind(path, 0), 0u) << e.what();
    }
  };
  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x10;
  expect_error(flipped, "CRC32 mismatch");
  expect_error(good.substr(0, good.size() - 100), "truncated");
  expect_error(good.substr(0, 10), "too short");
  std::string version = good;
  version[8] = 7;
  expect_error(version, "map version 7, this build reads version 1");
  expect_error("PLY?" + good, "bad magic");
  EXPECT_THROW(ReadMap(Path("absent.rgm")), DataError);
}

TEST_F(MapFiles, PlyHasThe3dgsLayout) {
  const GaussianMap map = ExampleMap();
  ExportPly(Path("map.ply"), map);
  const std::string bytes = ReadBytes(Path("map.ply"));
  const std::size_t end = bytes.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  const std::string header = bytes.substr(0, end);
  std::size_t properties = 0;
  for (std::size_t at = header.find("property float"); at != std::string::npos;
       at = header.find("property float", at + 1)) {
    ++properties;
  }
  EXPECT_EQ(properties, 62u);
  for (const char* name : {"f_dc_0", "f_rest_44", "opacity", "scale_2", "rot_3", "nz"}) {
    EXPECT_NE(header.find(std::string("property float ") + name + "\n"), std::string::npos) << name;
  }
  const std::size_t data = end + std::string("end_header\n").size();
  ASSERT_EQ(bytes.size() - data, map.gaussians.size() * 62 * sizeof(float));
  // Vertex 1: position, grey level 0.5 c_0, scales = log principal stds, and
  // rotation * diag(exp(2 scale)) * rotation^T = covariance.
  float v[62];
  std::memcpy(v, bytes.data() + data + 62 * sizeof(float), sizeof(v));
  const Gaussian& g = map.gaussians[1];
  EXPECT_NEAR(v[0], g.mean.x(), 1e-5);
  EXPECT_NEAR(v[6], 0.5 * g.rcs.coefficients[0], 1e-6);
  EXPECT_EQ(v[6], v[8]);
  const Eigen::Quaterniond q(v[58], v[59], v[60], v[61]);
  const Eigen::Vector3d variances(std::exp(2 * v[55]), std::exp(2 * v[56]), std::exp(2 * v[57]));
  const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
  EXPECT_LT((R * variances.asDiagonal() * R.transpose() - g.covariance).norm(), 1e-5);
}

}  // namespace
}  // namespace radargauss
