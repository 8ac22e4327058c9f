// SPDX-License-Identifier: BSD-3-Clause
// SLAM's parts on their own (docs/design/slam.md, "SLAM"): the keyframe
// graph's nodes and odometry edges as computed by hand, the paths through
// the graph with and without a loop, a loop's local solve holding what it
// does not correct; the loop search finding a planted revisit and nothing
// else, leaving the graph as it found it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "radargauss/slam/keyframe_graph.hpp"
#include "radargauss/slam/loop_search.hpp"

namespace radargauss {
namespace {

Keyframe At(double path, double yaw = 0.0) {
  Keyframe keyframe;
  keyframe.path = path;
  keyframe.odometry_pose = SE3d(SO3d::Exp(Eigen::Vector3d(0.0, 0.0, yaw)), Eigen::Vector3d(path, 0.0, 0.0));
  return keyframe;
}

TEST(KeyframeGraph, NodesEdgesAndPathsAsComputedByHand) {
  SlamOptions options;
  options.odometry_translation_std = 0.05;
  options.odometry_drift = 0.02;
  options.odometry_rotation_std_deg = 0.1;
  options.odometry_drift_deg = 0.02;
  KeyframeGraph graph(options);
  for (int k = 0; k < 5; ++k) graph.Add(At(10.0 * k));
  ASSERT_EQ(graph.keyframes().size(), 5u);
  ASSERT_EQ(graph.graph().edges().size(), 4u);
  for (int k = 0; k < 5; ++k) {
    EXPECT_LT((graph.graph().poses()[k].translation() - Eigen::Vector3d(10.0 * k, 0, 0)).norm(), 1e-12);
  }
  // 10 m between keyframes: 1 / (0.05 + 0.02 * 10) and 1 / ((0.1 + 0.02 * 10) deg).
  const Eigen::Matrix<double, 6, 6>& w = graph.graph().edges()[2].sqrt_information;
  EXPECT_NEAR(w(0, 0), 4.0, 1e-12);
  EXPECT_NEAR(w(5, 5), 1.0 / (0.3 * M_PI / 180.0), 1e-9);
  EXPECT_EQ(w(0, 1), 0.0);
  EXPECT_FALSE(graph.graph().edges()[2].loop);

  const std::vector<double> along = graph.PathsFrom(4);
  EXPECT_EQ(along, (std::vector<double>{40, 30, 20, 10, 0}));
  // A loop from the last to the first is crossed for free.
  graph.AddLoopAndSolve(0, 4, graph.graph().poses()[0].Inverse() * graph.graph().poses()[4],
                        Eigen::Matrix<double, 6, 6>::Identity());
  EXPECT_EQ(graph.PathsFrom(4), (std::vector<double>{0, 10, 20, 10, 0}));
  EXPECT_EQ(graph.PathsFrom(2), (std::vector<double>{20, 10, 0, 10, 20}));
  const std::vector<double> paths = graph.PathsFrom(4);
  const GraphPrior prior = graph.PriorOf(1, 4, paths);
  EXPECT_EQ(prior.path, 10.0);
  EXPECT_LT((prior.expected.translation() - Eigen::Vector3d(30, 0, 0)).norm(), 1e-9);
  // A scan of keyframe 3, 2 m past its odometry pose.
  const SE3d scan(SO3d(), Eigen::Vector3d(32.0, 0.0, 0.0));
  EXPECT_LT((graph.PoseOf(3, scan).translation() - Eigen::Vector3d(32, 0, 0)).norm(), 1e-9);
}

// 30 keyframes 10 m apart with a drifting heading, a loop from 12 to 0
// solved whole, then a loop of 210 m from 29 to 8 with a 50 m margin: it
// frees the keyframes within 260 m of 29 (3 to 29) and holds 0 to 2 as they
// were; the whole solve then moves those too (they lie on the first loop,
// which shares edges with the second) and ends where one whole solve of
// both loops ends.
TEST(KeyframeGraph, ALoopSolvesWhatItCorrectsAndTheWholeSolveCompletesIt) {
  SlamOptions options;
  options.local_solve_margin = 50.0;
  KeyframeGraph local(options), whole(options);
  for (int k = 0; k < 30; ++k) {
    local.Add(At(10.0 * k, 0.002 * k));
    whole.Add(At(10.0 * k, 0.002 * k));
  }
  const auto truth = [](int from, int to) {  // no drift
    return At(10.0 * from).odometry_pose.Inverse() * At(10.0 * to).odometry_pose;
  };
  const Eigen::Matrix<double, 6, 6> weight = 100.0 * Eigen::Matrix<double, 6, 6>::Identity();
  local.AddLoopAndSolve(0, 12, truth(0, 12), weight);
  whole.AddLoopAndSolve(0, 12, truth(0, 12), weight);
  const std::vector<SE3d> before = local.graph().poses();
  local.CloseLoop(8, 29, truth(8, 29), weight, 210.0);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(local.graph().poses()[k].translation(), before[k].translation()) << k;
    EXPECT_EQ(local.graph().poses()[k].rotation().quaternion().coeffs(), before[k].rotation().quaternion().coeffs())
        << k;
  }
  EXPECT_GT((local.graph().poses()[29].translation() - before[29].translation()).norm(), 1e-2);
  const SE3d held = local.graph().poses()[2];
  local.SolveWhole();
  whole.AddLoopAndSolve(8, 29, truth(8, 29), weight);
  EXPECT_GT((local.graph().poses()[2].translation() - held.translation()).norm(), 1e-3);
  for (int k = 0; k < 30; ++k) {
    EXPECT_LT((local.graph().poses()[k].translation() - whole.graph().poses()[k].translation()).norm(), 1e-3) << k;
  }
}

// A place of its own for each seed: four walls (3 m high) and a dozen poles
// at random within 40 m, 2,000 points, in the keyframe's frame.
std::vector<RadarPoint> Place(std::uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<RadarPoint> points;
  const auto add = [&](const Eigen::Vector3d& at) {
    RadarPoint point;
    point.position = at;
    point.rcs = 10.0 * unit(random);
    points.push_back(point);
  };
  for (int wall = 0; wall < 4; ++wall) {
    const double angle = 2.0 * M_PI * unit(random), range = 10.0 + 25.0 * unit(random);
    const double heading = angle + M_PI / 2.0 + 0.6 * (unit(random) - 0.5), length = 10.0 + 15.0 * unit(random);
    const Eigen::Vector3d centre(range * std::cos(angle), range * std::sin(angle), 0.0);
    const Eigen::Vector3d along(std::cos(heading), std::sin(heading), 0.0);
    for (int i = 0; i < 400; ++i)
      add(centre + along * length * (unit(random) - 0.5) + Eigen::Vector3d(0, 0, 3.0 * unit(random)));
  }
  for (int pole = 0; pole < 12; ++pole) {
    const double angle = 2.0 * M_PI * unit(random), range = 5.0 + 35.0 * unit(random);
    for (int i = 0; i < 33; ++i) {
      add(Eigen::Vector3d(range * std::cos(angle), range * std::sin(angle), 4.0 * unit(random)));
    }
  }
  return points;
}

// Twenty keyframes 10 m apart on a straight road, each a place of its own,
// then the first place again 200 m on, its odometry pose 2 m off the
// first's: only the revisit finds a loop, to keyframe 0, at the identity
// (the same points), among the keyframes at least min_loop_path back; the
// search leaves the graph's edges and poses as it found them.
TEST(LoopSearch, FindsAPlantedRevisitAndNothingElse) {
  const SlamOptions options;
  KeyframeGraph graph(options);
  LoopSearch search(options);
  for (int k = 0; k <= 20; ++k) {
    Keyframe keyframe = At(10.0 * k);
    keyframe.points = Place(k == 20 ? 1 : std::uint32_t(k + 1));
    if (k == 20) keyframe.odometry_pose = SE3d(SO3d(), Eigen::Vector3d(2.0, 0.0, 0.0));
    graph.Add(keyframe);
    search.AddPlace(graph.keyframes()[std::size_t(k)].points);
    const std::size_t edges = graph.graph().edges().size();
    const LoopSearchResult found = search.Search(k, graph);
    EXPECT_EQ(graph.graph().edges().size(), edges);
    if (k < 20) {
      EXPECT_FALSE(found.accepted.has_value()) << "keyframe " << k;
      continue;
    }
    EXPECT_EQ(found.eligible, (std::vector<int>{0, 1, 2, 3, 4, 5}));
    ASSERT_TRUE(found.accepted.has_value());
    const LoopCandidate& loop = found.outcomes[*found.accepted];
    EXPECT_EQ(loop.candidate, 0);
    EXPECT_EQ(loop.query, 20);
    EXPECT_LT(loop.check.relative.translation().norm(), 0.05);
    EXPECT_LT(loop.check.relative.rotation().Log().norm(), 0.2 * M_PI / 180.0);
  }
  EXPECT_GT(search.candidates().size(), 0u);
}

}  // namespace
}  // namespace radargauss
