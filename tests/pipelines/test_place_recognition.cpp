// SPDX-License-Identifier: BSD-3-Clause
// Place recognition: a yaw-rotated, shifted and noisy copy of a place
// retrieves that place among others with the yaw the sector multiple nearest it (Scan
// Context, each channel) or the angle step nearest it up to pi (the Radon descriptor);
// verification recovers a planted relative pose and refuses another place.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

#include "radargauss/slam/loop_verification.hpp"
#include "radargauss/slam/place_recognition.hpp"
#include "radargauss/slam/radon_descriptor.hpp"
#include "radargauss/slam/scan_context.hpp"

namespace radargauss {
namespace {

// A place: walls, poles and parked cars as point clusters with their own RCS.
std::vector<RadarPoint> RandomPlace(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> noise;
  std::vector<RadarPoint> points;
  for (int object = 0; object < 40; ++object) {
    const Eigen::Vector3d centre(60.0 * uniform(rng), 60.0 * uniform(rng), 0.0);
    const Eigen::Vector3d extent(4.0 * std::abs(uniform(rng)) + 0.2, 4.0 * std::abs(uniform(rng)) + 0.2,
                                 2.0 * std::abs(uniform(rng)) + 0.3);
    const double rcs = 15.0 * uniform(rng);
    for (int k = 0; k < 15; ++k) {
      RadarPoint point;
      point.position =
          centre + extent.cwiseProduct(Eigen::Vector3d(uniform(rng), uniform(rng), std::abs(uniform(rng))));
      point.rcs = rcs + noise(rng);
      points.push_back(point);
    }
  }
  return points;
}

// The place seen from a frame turned by yaw and moved by `shift`: p_q = R^T (p - shift).
std::vector<RadarPoint> SeenFrom(const std::vector<RadarPoint>& place, double yaw, const Eigen::Vector3d& shift,
                                 std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::vector<RadarPoint> seen = place;
  for (RadarPoint& point : seen) {
    point.position =
        R.transpose() * (point.position - shift) + 0.05 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    point.rcs += noise(rng);
  }
  return seen;
}

double AngleBetween(double a, double b) { return std::abs(std::remainder(a - b, 2.0 * M_PI)); }

TEST(ScanContext, RotatedCopyRetrievesThePlaceWithItsYaw) {
  for (const ScanContextChannel channel :
       {ScanContextChannel::kGeometric, ScanContextChannel::kRcs, ScanContextChannel::kBoth}) {
    ScanContextOptions options;
    options.channel = channel;
    std::vector<ScanContext> places;
    for (std::uint32_t seed = 1; seed <= 10; ++seed) places.push_back(MakeScanContext(RandomPlace(seed), options));
    const double sector = 2.0 * M_PI / options.sectors;
    for (const double yaw : {0.0, 0.3, 1.7, -2.5, 3.1}) {
      const ScanContext query =
          MakeScanContext(SeenFrom(RandomPlace(4), yaw, Eigen::Vector3d(0.4, -0.3, 0.0), 99), options);
      int best = -1;
      ScanContextMatch best_match;
      for (int p = 0; p < int(places.size()); ++p) {
        const ScanContextMatch match = CompareScanContexts(query, places[p], options);
        if (best < 0 || match.distance < best_match.distance) {
          best = p;
          best_match = match;
        }
      }
      EXPECT_EQ(best, 3) << "yaw " << yaw << ", channel " << int(channel);
      // The sector multiple nearest the yaw (measured within 0.40 sector): one sector off fails.
      EXPECT_LE(AngleBetween(best_match.yaw, yaw), 0.5 * sector) << "yaw " << yaw << ", channel " << int(channel);
      EXPECT_LT((query.ring_key - places[3].ring_key).norm(), 0.35);
    }
  }
}

// A query turned by k sectors, without a shift: the yaw is exactly k sectors
// and the aligned distance small.
TEST(ScanContext, ExactSectorTurnGivesItsShift) {
  ScanContextOptions options;
  const std::vector<RadarPoint> place = RandomPlace(5);
  const ScanContext candidate = MakeScanContext(place, options);
  const double sector = 2.0 * M_PI / options.sectors;
  for (const int k : {1, 7, 30, 59}) {
    const ScanContext query = MakeScanContext(SeenFrom(place, k * sector, Eigen::Vector3d::Zero(), 3), options);
    const ScanContextMatch match = CompareScanContexts(query, candidate, options);
    EXPECT_LT(AngleBetween(match.yaw, k * sector), 1e-9) << k;  // the very shift: one sector off fails
    EXPECT_LT(match.distance, 0.1) << k;
  }
}

TEST(ScanContext, EmptyAndInvalid) {
  ScanContextOptions options;
  const ScanContext empty = MakeScanContext({}, options);
  EXPECT_EQ(empty.ring_key.sum(), 0.0);
  EXPECT_EQ(CompareScanContexts(empty, MakeScanContext(RandomPlace(1), options), options).distance, 1.0);
  options.sectors = 0;
  EXPECT_THROW(MakeScanContext({}, options), std::invalid_argument);
  ScanContextOptions other;
  other.rings = 10;
  EXPECT_THROW(CompareScanContexts(empty, MakeScanContext({}, other), ScanContextOptions{}), std::invalid_argument);
}

// The descriptors' own validators are their tables' rows, the same that
// place recognition's scan_context_* and radon_* flags state: a value past
// a row's end is refused by both, naming the option.
TEST(PlaceDescriptors, ValidateByTheRowsTheirFlagsState) {
  const auto refused = [](const std::function<void()>& validate, const std::string& name) {
    try {
      validate();
      ADD_FAILURE() << name << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  };
  ScanContextOptions rings;
  rings.rings = 1001;  // the row is In(1, 1000)
  refused([&] { ValidateScanContextOptions(rings); }, "rings");
  RadonOptions angles;
  angles.angles = 1001;
  refused([&] { ValidateRadonOptions(angles); }, "angles");
  PlaceRecognitionOptions place;
  place.radon.angles = 1001;
  refused([&] { ValidateOptions(place); }, "radon_angles");
  place.radon.angles = 1000;
  ValidateOptions(place);
  ValidateRadonOptions(place.radon);
  ScanContextOptions floor;
  floor.rcs_floor = std::nan("");
  refused([&] { ValidateScanContextOptions(floor); }, "rcs_floor");
}

// The Radon descriptor does not change with a translation: a copy shifted by
// 6 m (where Scan Context's bins move) still finds its place.
TEST(RadonDescriptor, ShiftedRotatedCopyRetrievesThePlaceWithItsYaw) {
  RadonOptions options;
  std::vector<RadonDescriptor> places;
  for (std::uint32_t seed = 1; seed <= 10; ++seed) places.push_back(MakeRadonDescriptor(RandomPlace(seed), options));
  const double step = M_PI / options.angles;
  for (const double yaw : {0.0, 0.3, 1.7, -2.5, 3.1}) {
    const RadonDescriptor query =
        MakeRadonDescriptor(SeenFrom(RandomPlace(4), yaw, Eigen::Vector3d(4.0, -4.5, 0.0), 99), options);
    int best = -1;
    RadonMatch best_match;
    std::vector<double> key_distances;
    for (int p = 0; p < int(places.size()); ++p) {
      const RadonMatch match = CompareRadonDescriptors(query, places[p], options);
      key_distances.push_back((query.key - places[p].key).norm());
      if (best < 0 || match.distance < best_match.distance) {
        best = p;
        best_match = match;
      }
    }
    EXPECT_EQ(best, 3) << "yaw " << yaw;
    // Known up to pi: the nearer of yaw and yaw - pi, the angle step nearest
    // the yaw (measured within 0.47 step): one step off fails.
    EXPECT_LE(std::min(AngleBetween(best_match.yaw, yaw), AngleBetween(best_match.yaw - M_PI, yaw)), 0.5 * step)
        << "yaw " << yaw;
    EXPECT_EQ(std::min_element(key_distances.begin(), key_distances.end()) - key_distances.begin(), 3) << yaw;
  }
  RadonOptions bad;
  bad.angles = 1;
  EXPECT_THROW(MakeRadonDescriptor({}, bad), std::invalid_argument);
  EXPECT_EQ(CompareRadonDescriptors(MakeRadonDescriptor({}, options), places[0], options).distance, 1.0);
}

// A planted relative pose, 3 m and 25 deg from the descriptor's guess of 20
// deg: verification recovers it; another place is refused and says why.
// The bird's-eye search finds a planted whole-cell shift with every query
// cell overlapping; a few far points (a hostile place, 1e5 m to 3e9 m away)
// change neither the answer nor the memory (no dense grid over their span).
TEST(LoopVerification, BirdsEyeFindsAPlantedShiftWhateverTheExtent) {
  const double cell = 0.5;
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> uniform(-80, 80);
  std::vector<Eigen::Vector3d> candidate, query;
  const Eigen::Vector2i planted(3, -5);
  for (int k = 0; k < 300; ++k) {
    const Eigen::Vector2i c(uniform(rng), uniform(rng));
    candidate.emplace_back((c.x() + 0.5) * cell, (c.y() + 0.5) * cell, 0.0);
    query.emplace_back((c.x() - planted.x() + 0.5) * cell, (c.y() - planted.y() + 0.5) * cell, 1.0);
  }
  const auto [shift, overlap] = AlignBirdsEye(query, candidate, cell, 4.0);
  EXPECT_EQ(shift, planted.cast<double>() * cell);
  EXPECT_EQ(overlap, 1.0);
  for (const double far : {1e5, 3e9}) {
    std::vector<Eigen::Vector3d> wide = candidate;
    wide.emplace_back(far, -far, 0.0);
    wide.emplace_back(-far, far, 0.0);
    const auto [wide_shift, wide_overlap] = AlignBirdsEye(query, wide, cell, 4.0);
    EXPECT_EQ(wide_shift, shift) << far;
    EXPECT_EQ(wide_overlap, overlap) << far;
  }
  EXPECT_EQ(AlignBirdsEye({}, candidate, cell, 4.0).second, 0.0);
}

TEST(LoopVerification, RecoversAPlantedLoopAndRefusesAnotherPlace) {
  const std::vector<RadarPoint> place = RandomPlace(7);
  const double yaw = 25.0 * M_PI / 180.0;
  const Eigen::Vector3d shift(3.0, -2.0, 0.0);
  const std::vector<RadarPoint> query = SeenFrom(place, yaw, shift, 5);
  const SE3d planted(SO3d(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()))), shift);
  LoopVerificationOptions options;
  const LoopCheck check = VerifyLoop(query, place, 20.0 * M_PI / 180.0, GraphPrior{planted, 300.0}, options);
  ASSERT_TRUE(check.accepted) << check.reason;
  EXPECT_LT((check.relative.translation() - shift).norm(), 0.05);
  EXPECT_LT((check.relative.rotation().Inverse() * planted.rotation()).Log().norm(), 0.2 * M_PI / 180.0);
  EXPECT_GT(check.associated, 0.8);
  EXPECT_GT(check.sqrt_information.diagonal().minCoeff(), 0.0);

  const LoopCheck other = VerifyLoop(SeenFrom(RandomPlace(8), yaw, shift, 5), place, yaw, std::nullopt, options);
  EXPECT_FALSE(other.accepted);
  EXPECT_FALSE(other.reason.empty());
  // The right place, but far from where the graph has it after 20 m driven.
  const SE3d elsewhere(planted.rotation(), shift + Eigen::Vector3d(30.0, 0.0, 0.0));
  const LoopCheck inconsistent = VerifyLoop(query, place, yaw, GraphPrior{elsewhere, 20.0}, options);
  EXPECT_TRUE(VerifyLoop(query, place, yaw, std::nullopt, options).accepted);  // no prior, no consistency check
  EXPECT_FALSE(inconsistent.accepted);
  EXPECT_NE(inconsistent.reason.find("inconsistent"), std::string::npos) << inconsistent.reason;
}

// The bound of consistency by hand: max(min_drift, drift * path) metres and
// max(min_drift_deg, drift_deg * path) degrees, plus a margin; and the
// bird's-eye starts of a planted loop: the one at the true yaw lands on the
// planted shift and is consistent with a graph that has it there, and the
// other (half a turn off) is not, however wide the margin in metres.
TEST(LoopVerification, StartsAndTheirConsistencyWithTheGraph) {
  LoopVerificationOptions options;  // 5 m or 0.05 m per m, 10 deg or 0.05 deg per m
  const SE3d expected(SO3d(), Eigen::Vector3d(1.0, 2.0, 0.0));
  const auto moved = [&](double dx, double yaw_deg) {
    return expected * SE3d(SO3d::Exp(Eigen::Vector3d(0.0, 0.0, yaw_deg * M_PI / 180.0)), Eigen::Vector3d(dx, 0, 0));
  };
  GraphCorrection c = CorrectGraph(moved(4.9, 9.9), GraphPrior{expected, 20.0}, options);
  EXPECT_NEAR(c.translation, 4.9, 1e-12);
  EXPECT_NEAR(c.rotation_deg, 9.9, 1e-9);
  EXPECT_TRUE(c.consistent);
  EXPECT_FALSE(CorrectGraph(moved(5.1, 0.0), GraphPrior{expected, 20.0}, options).consistent);
  EXPECT_FALSE(CorrectGraph(moved(0.0, 10.1), GraphPrior{expected, 20.0}, options).consistent);
  EXPECT_TRUE(CorrectGraph(moved(5.1, 0.0), GraphPrior{expected, 20.0}, options, 0.2).consistent);
  EXPECT_TRUE(CorrectGraph(moved(11.9, 0.0), GraphPrior{expected, 240.0}, options).consistent);  // 0.05 * 240 = 12
  EXPECT_FALSE(CorrectGraph(moved(12.1, 0.0), GraphPrior{expected, 240.0}, options).consistent);
  EXPECT_TRUE(CorrectGraph(moved(0.0, 11.9), GraphPrior{expected, 240.0}, options).consistent);

  const std::vector<RadarPoint> place = RandomPlace(7);
  const double yaw = 25.0 * M_PI / 180.0;
  const Eigen::Vector3d shift(3.0, -2.0, 0.0);
  const SE3d planted(SO3d(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()))), shift);
  const std::vector<BirdsEyeStart> starts =
      BirdsEyeStarts(SeenFrom(place, yaw, shift, 5), place, {yaw, yaw - M_PI}, options);
  ASSERT_EQ(starts.size(), 2u);
  EXPECT_EQ(starts[0].yaw, yaw);
  EXPECT_LE((starts[0].shift - shift.head<2>()).norm(), options.bev_cell * std::sqrt(2.0));
  EXPECT_GT(starts[0].overlap, starts[1].overlap);
  const GraphPrior prior{planted, 20.0};
  EXPECT_TRUE(CorrectGraph(starts[0].pose(), prior, options).consistent);
  EXPECT_FALSE(CorrectGraph(starts[1].pose(), prior, options, 1000.0, options.start_margin_deg).consistent);
  EXPECT_EQ(BirdsEyeStarts({}, place, {yaw}, options)[0].overlap, 0.0);
}

}  // namespace
}  // namespace radargauss
