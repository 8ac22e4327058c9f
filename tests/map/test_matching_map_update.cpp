// SPDX-License-Identifier: BSD-3-Clause
// The updatable MatchingMap of odometry's local map: after any series of
// changes and removals every level answers as a map built from scratch from
// the Gaussians still listed.

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "radargauss/lie/so3.hpp"
#include "radargauss/map/matching_map.hpp"
#include "support/test_util.hpp"

namespace radargauss {
namespace {

using testing::RandomUnitVector;

Gaussian RandomGaussian(std::mt19937& rng, double extent) {
  std::uniform_real_distribution<double> position(-extent, extent), scale(0.1, 0.6);
  std::uniform_int_distribution<int> count(1, 40);
  Gaussian g;
  g.mean = Eigen::Vector3d(position(rng), position(rng), 0.2 * position(rng));
  const Eigen::Matrix3d axes = SO3d::Exp(RandomUnitVector(rng)).Matrix();
  const Eigen::Vector3d stds(scale(rng), scale(rng), scale(rng));
  g.covariance = ClampCovariance(axes * stds.array().square().matrix().asDiagonal() * axes.transpose(), 0.0);
  g.point_count = std::uint32_t(count(rng));
  return g;
}

// Every query of every level of `updated` gives the Gaussian (mean,
// information) that the same level of `rebuilt` gives; queries fall near the
// means of `updated`'s map, listed or not.
void ExpectSameAnswers(const MatchingMap& updated, const MatchingMap& rebuilt, std::mt19937& rng) {
  ASSERT_EQ(updated.levels(), rebuilt.levels());
  std::uniform_int_distribution<std::size_t> pick(0, updated.map().gaussians.size() - 1);
  std::normal_distribution<double> offset(0.0, 0.6);
  for (std::size_t level = 0; level < updated.levels(); ++level) {
    const double gate = level + 1 == updated.levels() ? 3.0 : updated.coarse_gate();
    int associated = 0;
    for (int trial = 0; trial < 4000; ++trial) {
      const Eigen::Vector3d p =
          updated.map().gaussians[pick(rng)].mean + Eigen::Vector3d(offset(rng), offset(rng), offset(rng));
      double d2_updated = 0.0, d2_rebuilt = 0.0;
      const int a = updated.level(level).Associate(p, gate * gate, &d2_updated);
      const int b = rebuilt.level(level).Associate(p, gate * gate, &d2_rebuilt);
      ASSERT_EQ(a >= 0, b >= 0) << "level " << level << " at " << p.transpose();
      if (a < 0) continue;
      ++associated;
      EXPECT_EQ(updated.level(level).Mean(a), rebuilt.level(level).Mean(b)) << "level " << level;
      EXPECT_EQ(d2_updated, d2_rebuilt);
      EXPECT_EQ(updated.level(level).Information(a), rebuilt.level(level).Information(b));
    }
    EXPECT_GT(associated, 1000) << "level " << level << ": too few queries hit a Gaussian to test anything";
  }
}

class MatchingMapUpdateTest : public ::testing::TestWithParam<CoarseLevels> {};

TEST_P(MatchingMapUpdateTest, AnswersAsRebuiltAfterChangesAndRemovals) {
  std::mt19937 rng(7);
  const double extent = 25.0;
  auto map = std::make_shared<GaussianMap>();
  for (int i = 0; i < 300; ++i) map->gaussians.push_back(RandomGaussian(rng, extent));
  MatchingMapOptions options;
  options.coarse = GetParam();
  options.updatable = true;
  MatchingMap updated(std::shared_ptr<const GaussianMap>(map), options);
  std::vector<char> live(map->gaussians.size(), 1);
  std::uniform_int_distribution<int> pick(0, 299);
  for (int round = 0; round < 12; ++round) {
    std::vector<std::uint32_t> changed, removed;
    for (int k = 0; k < 30; ++k) {  // moves, removals and new Gaussians in one update
      const std::uint32_t id = std::uint32_t(pick(rng));
      if (k % 3 == 0) {
        removed.push_back(id);
        live[id] = 0;
      } else {
        // A new Gaussian, or the same one nudged: it keeps most of its cells,
        // which other changes in the update touch.
        if (k % 3 == 1) {
          map->gaussians[id] = RandomGaussian(rng, extent);
        } else {
          map->gaussians[id].mean += 0.05 * RandomUnitVector(rng);
        }
        changed.push_back(id);
        live[id] = 1;
      }
    }
    for (const std::uint32_t id : changed) {  // a Gaussian both removed and changed stays (changed wins)
      live[id] = 1;
    }
    map->gaussians.push_back(RandomGaussian(rng, extent));
    live.push_back(1);
    changed.push_back(std::uint32_t(map->gaussians.size() - 1));
    updated.Update(changed, removed);
    GaussianMap listed;
    for (std::size_t i = 0; i < live.size(); ++i) {
      if (live[i]) listed.gaussians.push_back(map->gaussians[i]);
    }
    options.updatable = false;
    const MatchingMap rebuilt(listed, options);
    options.updatable = true;
    EXPECT_EQ(updated.indexed(), listed.gaussians.size());
    ExpectSameAnswers(updated, rebuilt, rng);
  }
}

INSTANTIATE_TEST_SUITE_P(CoarseLevels, MatchingMapUpdateTest,
                         ::testing::Values(CoarseLevels::kMerged, CoarseLevels::kInflated),
                         [](const auto& info) { return ToString(info.param); });

// Removing every Gaussian leaves levels that associate nothing, and the
// index's memory falls back once the stale lists are compacted.
TEST(MatchingMapUpdateTest, RemovingEverythingEmptiesEveryLevel) {
  std::mt19937 rng(3);
  auto map = std::make_shared<GaussianMap>();
  for (int i = 0; i < 2000; ++i) map->gaussians.push_back(RandomGaussian(rng, 30.0));
  MatchingMapOptions options;
  options.updatable = true;
  MatchingMap updated(std::shared_ptr<const GaussianMap>(map), options);
  const std::size_t full_bytes = updated.index().MemoryBytes();
  std::vector<std::uint32_t> all;
  for (std::uint32_t i = 0; i < 2000; ++i) all.push_back(i);
  updated.Update({}, all);
  EXPECT_EQ(updated.indexed(), 0u);
  for (std::size_t level = 0; level < updated.levels(); ++level) {
    for (const Gaussian& g : map->gaussians) EXPECT_EQ(updated.level(level).Associate(g.mean, 9.0), -1);
  }
  EXPECT_LT(updated.index().MemoryBytes(), full_bytes / 2);
}

// Gaussians that grow and shrink back leave the index no larger than it
// was: a Gaussian's list of cells gives its memory back when it changes.
TEST(MatchingMapUpdateTest, MemoryFollowsTheLiveGaussians) {
  std::mt19937 rng(5);
  auto map = std::make_shared<GaussianMap>();
  for (int i = 0; i < 400; ++i) map->gaussians.push_back(RandomGaussian(rng, 30.0));
  const std::vector<Gaussian> small = map->gaussians;
  MatchingMapOptions options;
  options.updatable = true;
  MatchingMap updated(std::shared_ptr<const GaussianMap>(map), options);
  std::vector<std::uint32_t> all;
  for (std::uint32_t i = 0; i < 400; ++i) all.push_back(i);
  updated.Update(all, {});  // the same Gaussians again: the steady state
  const std::size_t small_bytes = updated.index().MemoryBytes();
  for (Gaussian& g : map->gaussians) g.covariance *= 4.0;
  updated.Update(all, {});
  const std::size_t large_bytes = updated.index().MemoryBytes();
  map->gaussians = small;
  updated.Update(all, {});
  updated.Update(all, {});
  EXPECT_GT(large_bytes, 2 * small_bytes);
  EXPECT_LT(updated.index().MemoryBytes(), small_bytes * 11 / 10);
}

TEST(MatchingMapUpdateTest, StaticMapRefusesUpdates) {
  MatchingMap map{GaussianMap()};
  EXPECT_THROW(map.Update({}, {}), std::logic_error);
}

}  // namespace
}  // namespace radargauss
