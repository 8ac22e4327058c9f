// SPDX-License-Identifier: BSD-3-Clause
// Radar SLAM on a simulated drive of 1.8 laps around a small yard, with an
// odometry that forgets its map beyond 30 m and so drifts: the revisits are
// found, no false loop is accepted, the trajectory is closer to the truth
// than the odometry's, and the run is the same for any thread count. Then
// relocalisation of another run in the map it builds.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>

#include "radargauss/experiment/evaluation.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/map_tiles.hpp"
#include "radargauss/slam/radar_slam.hpp"
#include "radargauss/slam/relocalization.hpp"

namespace radargauss {
namespace {

const SimulatedSequence& Yard() {
  static const SimulatedSequence* drive = [] {
    SimulationConfig config;
    config.scans = 500;  // 300 m at 6 m/s: 1.8 laps of 166 m
    config.loop_length = 60.0;
    config.loop_width = 30.0;
    config.corner_radius = 8.0;
    config.poles = 12;
    config.parked_cars = 8;
    config.moving_cars = 1;
    config.min_detections = 100;
    config.max_detections = 200;
    config.max_range = 60.0;
    return new SimulatedSequence(Simulate(config));
  }();
  return *drive;
}

SlamOptions YardOptions() {
  SlamOptions options;
  options.odometry.map.active_radius = 30.0;
  options.min_loop_path = 100.0;
  options.place_recognition.candidates = 20;
  options.place_recognition.max_scan_context_distance = 0.6;
  options.place_merge_distance = 6.0;  // a revisit adds no place
  return options;
}

std::unique_ptr<RadarSlam> RunYard(const SlamOptions& options) {
  auto slam = std::make_unique<RadarSlam>(options);
  for (const RadarScan& scan : Yard().scans) slam->Register(scan);
  slam->Finish();
  return slam;
}

// The yard's SLAM run with the default Scan Context, shared by the tests.
const RadarSlam& YardSlam() {
  static const RadarSlam* slam = RunYard(YardOptions()).release();
  return *slam;
}

Eigen::Vector3d TruePosition(const Keyframe& keyframe) {
  return Yard().ground_truth.Interpolate(keyframe.stamp)->translation();
}

TEST(RadarSlam, ClosesTheYardsRevisitsWithoutAFalseLoop) {
  const RadarSlam* slam = &YardSlam();
  const std::vector<Keyframe>& keyframes = slam->keyframes();
  EXPECT_EQ(keyframes.size(), std::size_t(std::ceil(299.0 / 10.0)));
  // True revisits: a keyframe within 5 m of one at least min_loop_path back.
  int revisits = 0, closed = 0;
  for (std::size_t q = 0; q < keyframes.size(); ++q) {
    bool revisit = false;
    for (std::size_t c = 0; c < q; ++c) {
      revisit |= keyframes[q].path - keyframes[c].path >= 100.0 &&
                 (TruePosition(keyframes[q]) - TruePosition(keyframes[c])).norm() < 5.0;
    }
    revisits += revisit;
    for (const LoopCandidate& loop : slam->candidates())
      closed += revisit && loop.query == int(q) && loop.check.accepted;
  }
  std::size_t accepted = 0;
  for (const LoopCandidate& loop : slam->candidates()) {
    if (!loop.check.accepted) continue;
    ++accepted;
    const double apart = (TruePosition(keyframes[loop.query]) - TruePosition(keyframes[loop.candidate])).norm();
    EXPECT_LT(apart, 8.0) << "false loop " << loop.query << " -> " << loop.candidate;
    // The loop's measurement agrees with the truth.
    const SE3d truth = Yard().ground_truth.Interpolate(keyframes[loop.candidate].stamp)->Inverse() *
                       *Yard().ground_truth.Interpolate(keyframes[loop.query].stamp);
    EXPECT_LT((truth.Inverse() * loop.check.relative).translation().norm(), 0.5);
  }
  EXPECT_EQ(accepted, slam->loops());
  EXPECT_GE(revisits, 12);
  EXPECT_GE(closed, int(0.7 * revisits)) << closed << " of " << revisits;
  const Evaluation odometry = EvaluateTrajectory(slam->odometry().trajectory(), Yard().ground_truth);
  const Evaluation corrected = EvaluateTrajectory(slam->trajectory(), Yard().ground_truth);
  EXPECT_LT(corrected.ate_translation.rmse, 0.5 * odometry.ate_translation.rmse)
      << corrected.ate_translation.rmse << " against " << odometry.ate_translation.rmse;
  // Each scan follows its keyframe: a keyframe's own scan is exactly its graph pose.
  const std::vector<SE3d> poses = slam->Poses();
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    EXPECT_LT((poses[keyframes[k].scan].translation() - slam->graph().poses()[k].translation()).norm(), 1e-9);
  }
}

// Each scan's time, the front end and the back end apart: one per scan; run
// in Register, the back end's work falls on the scans that closed a
// keyframe (each keyframe once); run beside the odometry, it leaves them.
void ExpectScanTimes(const RadarSlam& slam) {
  ASSERT_EQ(slam.scan_times().size(), slam.odometry().steps().size());
  std::size_t closed = 0;
  double closing_back_end = 0.0, other_back_end = 0.0, keyframes_back_end = 0.0;
  for (std::size_t s = 0; s + 1 < slam.scan_times().size(); ++s) {  // the last scan's holds Finish's wait
    const ScanTime& t = slam.scan_times()[s];
    EXPECT_GT(t.front_end_ms, 0.0);
    EXPECT_GE(t.back_end_ms, 0.0);
    EXPECT_DOUBLE_EQ(t.total_ms(), t.front_end_ms + t.back_end_ms);
    closed += t.closed_keyframe;
    (t.closed_keyframe ? closing_back_end : other_back_end) += t.back_end_ms;
  }
  for (const Keyframe& keyframe : slam.keyframes()) {
    EXPECT_GT(keyframe.back_end_ms(), 0.0);
    keyframes_back_end += keyframe.back_end_ms();
  }
  EXPECT_EQ(closed + slam.scan_times().back().closed_keyframe, slam.keyframes().size());
  if (slam.asynchronous()) {
    EXPECT_LT(closing_back_end + other_back_end, 0.5 * keyframes_back_end);
  } else {
    EXPECT_GT(closing_back_end, other_back_end);  // describing and searching a place is the back end's work
  }
  const SlamSummary summary = Summarise(slam);
  EXPECT_EQ(summary.asynchronous, slam.asynchronous());
  EXPECT_LE(summary.total_median_ms, summary.total_p90_ms);
  EXPECT_LE(summary.total_p90_ms, summary.total_p99_ms);
  EXPECT_LE(summary.total_p99_ms, summary.total_max_ms);
  EXPECT_LE(summary.keyframe_median_ms, summary.keyframe_p99_ms);
  EXPECT_LE(summary.keyframe_p99_ms, summary.keyframe_max_ms);
}

// The Radon descriptor's run with one thread everywhere (TBB and the graph,
// the back end in Register) against two and eight threads (the back end on
// its own thread, two threads for the graph): the same loops and the same
// poses to the bit, and each scan's time kept either way.
TEST(RadarSlam, SameRunForAnyThreadCount) {
  SlamOptions one = YardOptions();
  one.place_recognition.descriptor = "radon";
  one.graph.threads = 1;
  SlamOptions more = one;
  more.graph.threads = 2;
  std::unique_ptr<RadarSlam> a;
  {
    const tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    a = RunYard(one);
  }
  EXPECT_FALSE(a->asynchronous());
  ExpectScanTimes(*a);
  EXPECT_GT(a->loops(), 0u);
  const std::vector<SE3d> pa = a->Poses();
  for (const int threads : {2, 8}) {
    std::unique_ptr<RadarSlam> b;
    {
      const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
      b = RunYard(more);
    }
    EXPECT_TRUE(b->asynchronous()) << threads;
    ExpectScanTimes(*b);
    EXPECT_EQ(a->loops(), b->loops()) << threads;
    EXPECT_EQ(a->place_map_bytes(), b->place_map_bytes()) << threads;
    EXPECT_EQ(a->place_map_parts().size(), b->place_map_parts().size()) << threads;
    const std::vector<SE3d> pb = b->Poses();
    ASSERT_EQ(pa.size(), pb.size());
    for (std::size_t s = 0; s < pa.size(); ++s) {
      ASSERT_EQ(pa[s].translation(), pb[s].translation()) << threads << " threads, scan " << s;
      ASSERT_EQ(pa[s].rotation().quaternion().coeffs(), pb[s].rotation().quaternion().coeffs()) << s;
    }
  }
}

// Another run of the yard's world (another noise seed, starting 70 m along
// the loop) located in the map of the yard's SLAM run with no initial pose:
// the first fix within 0.5 m and 2.5 deg of the truth (in the map's frame,
// SLAM's trajectory aligned to the truth), every reported pose within 1 m;
// a run in another yard gets no fix and reports no pose.
SimulatedSequence SecondRun(bool same_world) {
  SimulationConfig config = Yard().config;
  config.scans = 120;
  config.seed = 7;
  config.world_seed = 1;  // the yard's objects
  config.start_offset = 70.0;
  if (!same_world) {  // another yard: other walls, other objects
    config.loop_length = 90.0;
    config.loop_width = 45.0;
    config.world_seed = 99;
  }
  return Simulate(config);
}

TEST(Relocalizer, FindsASecondRunInTheSlamMapAndRefusesAnotherYard) {
  const RadarSlam* slam = &YardSlam();
  const GaussianMap map = BuildPlaceMap(Yard().scans, *slam);
  // The second lap's keyframes merged into the first's places: fewer places,
  // and every keyframe within the merge distance of one.
  ASSERT_LT(map.places.size(), slam->keyframes().size() * 3 / 4);
  for (std::size_t k = 0; k < slam->keyframes().size(); ++k) {
    double nearest = INFINITY;
    for (const MapPlace& place : map.places) {
      nearest = std::min(nearest, (place.pose.translation() - slam->graph().poses()[k].translation()).norm());
    }
    EXPECT_LE(nearest, YardOptions().place_merge_distance) << k;
  }
  const SE3d truth_from_map = EvaluateTrajectory(slam->trajectory(), Yard().ground_truth).alignment;
  RelocalizationOptions options;
  options.place_recognition = YardOptions().place_recognition;
  {
    const SimulatedSequence second = SecondRun(true);
    Relocalizer relocalizer(map, options);
    for (const RadarScan& scan : second.scans) relocalizer.Register(scan);
    ASSERT_TRUE(relocalizer.first_fix().has_value());
    EXPECT_LT(*relocalizer.first_fix(), 60u);
    std::size_t reported = 0;
    for (std::size_t k = 0; k < relocalizer.steps().size(); ++k) {
      const RelocalizationStep& step = relocalizer.steps()[k];
      if (k < *relocalizer.first_fix()) {
        EXPECT_FALSE(step.fixed) << k;
      }
      if (!step.fixed) continue;
      ++reported;
      const SE3d error = (truth_from_map * step.pose).Inverse() * *second.ground_truth.Interpolate(step.stamp);
      const double limit = k == *relocalizer.first_fix() ? 0.5 : 1.0;
      EXPECT_LT(error.translation().norm(), limit) << "scan " << k;
      if (k == *relocalizer.first_fix()) {
        EXPECT_LT(error.rotation().Log().norm() * 180.0 / M_PI, 2.5);
      }
    }
    EXPECT_GT(reported, (second.scans.size() - *relocalizer.first_fix()) / 2);
  }
  {
    const SimulatedSequence elsewhere = SecondRun(false);
    Relocalizer relocalizer(map, options);
    for (const RadarScan& scan : elsewhere.scans) {
      EXPECT_FALSE(relocalizer.Register(scan).fixed);
    }
    EXPECT_FALSE(relocalizer.first_fix().has_value());
    EXPECT_GT(relocalizer.candidates().size(), 0u);
  }
  {
    // Every place twice, the copy 50 m away: each verified place has a twin
    // that verifies as well and disagrees, so no submap may make a fix.
    GaussianMap aliased = map;
    for (const MapPlace& place : map.places) {
      MapPlace copy = place;
      copy.pose = SE3d(SO3d(), Eigen::Vector3d(50.0, 0.0, 0.0)) * place.pose;
      aliased.places.push_back(copy);
    }
    Relocalizer relocalizer(aliased, options);
    for (const RadarScan& scan : SecondRun(true).scans) relocalizer.Register(scan);
    EXPECT_FALSE(relocalizer.first_fix().has_value());
    std::size_t ambiguous = 0;
    for (const PlaceCandidate& c : relocalizer.candidates()) ambiguous += c.check.reason.rfind("ambiguous", 0) == 0;
    EXPECT_GT(ambiguous, 0u);
  }
  GaussianMap without_places = map;
  without_places.places.clear();
  EXPECT_THROW(Relocalizer(without_places, options), DataError);
}

// The map file and the map written as tiles of 40 m, read back whole,
// relocalise the second run alike to the bit.
TEST(Relocalizer, TheMapAsTilesRelocalisesTheSame) {
  const std::string dir = std::filesystem::temp_directory_path() / ("radargauss_tiles_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  WriteMap(dir + "/map.rgm", BuildPlaceMap(Yard().scans, YardSlam()));
  const GaussianMap map = ReadMapOrTiles(dir + "/map.rgm");
  WriteMapTiles(dir + "/tiles", map, 40.0);
  const GaussianMap tiled = ReadMapOrTiles(dir + "/tiles");
  std::filesystem::remove_all(dir);
  RelocalizationOptions options;
  options.place_recognition = YardOptions().place_recognition;
  Relocalizer a(map, options), b(tiled, options);
  for (const RadarScan& scan : SecondRun(true).scans) {
    const RelocalizationStep sa = a.Register(scan), sb = b.Register(scan);
    ASSERT_EQ(sa.fixed, sb.fixed);
    ASSERT_EQ(sa.pose.translation(), sb.pose.translation());
    ASSERT_EQ(sa.pose.rotation().quaternion().coeffs(), sb.pose.rotation().quaternion().coeffs());
  }
  ASSERT_TRUE(a.first_fix().has_value());
  EXPECT_EQ(a.first_fix(), b.first_fix());
}

// With a loop spacing of 25 m, no accepted loop's query lies within 25 m
// driven after the previous one's, and the revisits are still closed.
TEST(RadarSlam, LoopSpacingLeavesTheKeyframesAfterALoopUnsearched) {
  SlamOptions options = YardOptions();
  options.loop_spacing = 25.0;
  const std::unique_ptr<RadarSlam> spaced = RunYard(options);
  ASSERT_GT(spaced->loops(), 0u);
  EXPECT_LT(spaced->loops(), YardSlam().loops());
  int last = -1;  // the last accepted loop's query
  for (const LoopCandidate& c : spaced->candidates()) {
    if (last >= 0 && c.query != last) {
      EXPECT_GE(spaced->keyframes()[std::size_t(c.query)].path - spaced->keyframes()[std::size_t(last)].path, 25.0)
          << "keyframe " << c.query << " searched";
    }
    if (c.check.accepted) last = c.query;
  }
}

// RadarSlam's parts replayed by hand over the yard's keyframes, in the
// order it calls them (a keyframe into the graph, its place, its search, the
// accepted loop into the graph): the same verdicts and poses, and a search
// that leaves the graph as it found it.
TEST(RadarSlam, ItsPartsReplayedByHandGiveTheSameRun) {
  const RadarSlam& slam = YardSlam();
  const SlamOptions options = YardOptions();
  KeyframeGraph graph(options);
  LoopSearch search(options);
  for (std::size_t k = 0; k < slam.keyframes().size(); ++k) {
    graph.Add(slam.keyframes()[k]);
    search.AddPlace(graph.keyframes()[k].points);
    const std::size_t edges = graph.graph().edges().size();
    const SE3d last = graph.graph().poses().back();
    const LoopSearchResult found = search.Search(int(k), graph);
    ASSERT_EQ(graph.graph().edges().size(), edges);
    ASSERT_EQ(graph.graph().poses().back().translation(), last.translation());
    if (found.accepted) {
      const LoopCandidate& loop = found.outcomes[*found.accepted];
      graph.CloseLoop(loop.candidate, int(k), loop.check.relative, loop.check.sqrt_information, found.path);
    }
  }
  graph.SolveWhole();
  ASSERT_EQ(search.candidates().size(), slam.candidates().size());
  for (std::size_t i = 0; i < slam.candidates().size(); ++i) {
    EXPECT_EQ(search.candidates()[i].query, slam.candidates()[i].query);
    EXPECT_EQ(search.candidates()[i].candidate, slam.candidates()[i].candidate);
    EXPECT_EQ(search.candidates()[i].check.accepted, slam.candidates()[i].check.accepted) << i;
    EXPECT_EQ(search.candidates()[i].check.reason, slam.candidates()[i].check.reason) << i;
  }
  EXPECT_GT(slam.loops(), 0u);
  for (std::size_t k = 0; k < slam.keyframes().size(); ++k) {
    EXPECT_EQ(graph.graph().poses()[k].translation(), slam.graph().poses()[k].translation()) << k;
  }
}

// Verification targets kept between searches (the default) or built anew for
// every candidate (one kept): the same loops and poses, fewer builds.
TEST(RadarSlam, KeptVerificationTargetsChangeNothing) {
  SlamOptions rebuilt = YardOptions();
  rebuilt.verification.kept_targets = 1;
  const std::unique_ptr<RadarSlam> a = RunYard(rebuilt);
  const RadarSlam& b = YardSlam();
  ASSERT_GT(b.loops(), 0u);
  EXPECT_EQ(a->loops(), b.loops());
  EXPECT_GT(a->verification_targets_built(), b.verification_targets_built());
  const std::vector<SE3d> pa = a->Poses(), pb = b.Poses();
  ASSERT_EQ(pa.size(), pb.size());
  for (std::size_t s = 0; s < pa.size(); ++s) {
    ASSERT_EQ(pa[s].translation(), pb[s].translation()) << s;
    ASSERT_EQ(pa[s].rotation().quaternion().coeffs(), pb[s].rotation().quaternion().coeffs()) << s;
  }
}

// The bytes of the points held by the keyframes that opened before scan `end`.
std::size_t HeldBytesBefore(const RadarSlam& slam, std::size_t end) {
  std::size_t bytes = 0;
  for (const PlaceMapPart& part : slam.place_map_parts()) {
    if (part.first_scan >= end) continue;
    for (const StaticScanPoints& scan : part.scans) bytes += scan.MemoryBytes();
  }
  return bytes;
}

constexpr std::size_t kYardLapScans = 277;  // 166 m at 0.6 m per scan

// Every keyframe holding its points (place_map_revisits): the map from the
// held points is the map from every registered scan, Gaussian for Gaussian,
// and the points held grow with the drive (1.8 laps: over 1.6x the first's).
TEST(RadarSlam, TheHeldPointsGiveTheMapOfEveryScan) {
  SlamOptions options = YardOptions();
  options.place_map_revisits = true;
  const std::unique_ptr<RadarSlam> slam = RunYard(options);
  ASSERT_EQ(slam->place_map_parts().size(), slam->keyframes().size());
  const GaussianMap held = BuildPlaceMap(*slam), scanned = BuildPlaceMap(Yard().scans, *slam);
  ASSERT_GT(held.gaussians.size(), 100u);
  ASSERT_EQ(held.gaussians.size(), scanned.gaussians.size());
  for (std::size_t g = 0; g < held.gaussians.size(); ++g) {
    ASSERT_EQ(held.gaussians[g].mean, scanned.gaussians[g].mean) << g;
    ASSERT_EQ(held.gaussians[g].covariance, scanned.gaussians[g].covariance) << g;
    ASSERT_EQ(held.gaussians[g].rcs.coefficients, scanned.gaussians[g].rcs.coefficients) << g;
  }
  ASSERT_EQ(held.places.size(), scanned.places.size());
  EXPECT_GT(double(slam->place_map_bytes()), 1.6 * double(HeldBytesBefore(*slam, kYardLapScans)));
}

// A keyframe that closes within place_merge_distance of a held one holds no
// points: after the loops of the second lap the memory stays the first
// lap's (within a quarter), and the map still covers the whole yard.
TEST(RadarSlam, ARevisitHoldsNoPointsSoItsMemoryIsBoundedByThePlace) {
  const RadarSlam& slam = YardSlam();
  ASSERT_GT(slam.loops(), 0u);
  const std::size_t first_lap = HeldBytesBefore(slam, kYardLapScans);
  ASSERT_GT(first_lap, 0u);
  EXPECT_LT(slam.place_map_parts().size(), slam.keyframes().size() * 3 / 4);
  EXPECT_LE(double(slam.place_map_bytes()), 1.25 * double(first_lap));
  const GaussianMap map = BuildPlaceMap(slam);
  const GaussianMap every = BuildPlaceMap(Yard().scans, slam);
  EXPECT_GT(map.gaussians.size(), every.gaussians.size() / 2);
  EXPECT_EQ(map.places.size(), every.places.size());
  SlamOptions none = YardOptions();
  none.hold_map_points = false;
  const RadarSlam empty(none);
  EXPECT_THROW(BuildPlaceMap(empty), DataError);
}

bool HoldsPoints(const RadarSlam& slam, int keyframe) {
  const std::vector<PlaceMapPart>& parts = slam.place_map_parts();
  return std::any_of(parts.begin(), parts.end(),
                     [&](const PlaceMapPart& part) { return part.keyframe == std::size_t(keyframe); });
}

// Without revisit_candidates each place has one loop candidate, its newest
// visit, where the default compares every visit: fewer candidates compared,
// the replaced visits' submaps released unless they are places, and the
// yard's loops still close and correct the drift.
TEST(RadarSlam, WithoutRevisitCandidatesEachPlaceIsAnsweredByItsNewestVisit) {
  const RadarSlam& every = YardSlam();
  const std::vector<LoopCandidate>& all = every.candidates();
  EXPECT_TRUE(std::any_of(all.begin(), all.end(),
                          [&](const LoopCandidate& c) { return !c.injected && !HoldsPoints(every, c.candidate); }));
  SlamOptions options = YardOptions();
  options.revisit_candidates = false;
  const std::unique_ptr<RadarSlam> slam = RunYard(options);
  ASSERT_GT(slam->loops(), 0u);
  EXPECT_LT(slam->candidates().size(), all.size());
  const std::vector<bool>& candidates = slam->loop_candidates();
  const std::vector<bool>& first_visits = slam->first_visits();
  const std::vector<Keyframe>& keyframes = slam->keyframes();
  ASSERT_EQ(candidates.size(), keyframes.size());
  std::size_t replaced = 0;
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    EXPECT_GT(keyframes[k].submap_points, 0u) << k;
    if (candidates[k]) continue;
    ++replaced;
    EXPECT_EQ(keyframes[k].points.empty(), !first_visits[k]) << k;
  }
  EXPECT_GT(replaced, keyframes.size() / 4);
  EXPECT_TRUE(every.loop_candidates().empty());  // the default keeps none apart: every keyframe is one
  const Evaluation odometry = EvaluateTrajectory(slam->odometry().trajectory(), Yard().ground_truth);
  const Evaluation corrected = EvaluateTrajectory(slam->trajectory(), Yard().ground_truth);
  EXPECT_LT(corrected.ate_translation.rmse, 0.5 * odometry.ate_translation.rmse);
}

TEST(RadarSlam, RefusesBadOptions) {
  SlamOptions options;
  options.submap_distance = 0.0;
  EXPECT_THROW(RadarSlam{options}, std::invalid_argument);
  options = SlamOptions();
  options.verification.min_associated = 2.0;
  EXPECT_THROW(RadarSlam{options}, std::invalid_argument);
  RelocalizationOptions relocalization;
  relocalization.confirm_window = 0;
  EXPECT_THROW(ValidateOptions(relocalization), std::invalid_argument);
  PlaceRecognitionOptions sift;
  sift.descriptor = "sift";
  EXPECT_THROW(MakePlaceDescriptor(sift), std::invalid_argument);
  const std::vector<std::string> names = PlaceDescriptorNames();
  EXPECT_EQ(std::vector<std::string>(names.begin(), names.begin() + 2),
            (std::vector<std::string>{"scan-context", "radon"}));
}

// A descriptor written here, through the interface alone: the histogram of
// the submap's ranges (rotation-invariant), compared by the keys' distance,
// with no yaw (the yard is revisited with the same heading).
class RangeHistogram final : public PlaceDescriptor {
 public:
  std::shared_ptr<const PlaceDescription> Describe(const std::vector<RadarPoint>& submap) const override {
    auto description = std::make_shared<PlaceDescription>();
    description->key = Eigen::VectorXd::Zero(12);
    for (const RadarPoint& point : submap) {
      description->key[std::min<int>(11, int(point.position.head<2>().norm() / 5.0))] += 1.0;
    }
    if (description->key.norm() > 0.0) description->key.normalize();
    return description;
  }
  PlaceComparison Compare(const PlaceDescription& query, const PlaceDescription& candidate) const override {
    return {0.5 * (query.key - candidate.key).norm(), {0.0}};
  }
  double MaxDistance() const override { return 0.2; }
};
const bool range_histogram_registered = RegisterPlaceDescriptor(
    "range-histogram", [](const PlaceRecognitionOptions&) { return std::make_unique<RangeHistogram>(); });

TEST(RadarSlam, ANewDescriptorRunsThroughTheInterfaceAlone) {
  ASSERT_TRUE(range_histogram_registered);
  EXPECT_THROW(
      RegisterPlaceDescriptor("range-histogram",
                              [](const PlaceRecognitionOptions&) { return std::make_unique<RangeHistogram>(); }),
      std::invalid_argument);
  SlamOptions options = YardOptions();
  options.place_recognition.descriptor = "range-histogram";
  const std::unique_ptr<RadarSlam> slam = RunYard(options);
  EXPECT_GT(slam->candidates().size(), 0u);
  EXPECT_GT(slam->loops(), 0u);
  for (const LoopCandidate& loop : slam->candidates()) {
    if (!loop.check.accepted) continue;
    EXPECT_LT((TruePosition(slam->keyframes()[loop.query]) - TruePosition(slam->keyframes()[loop.candidate])).norm(),
              8.0);
  }
}

}  // namespace
}  // namespace radargauss
