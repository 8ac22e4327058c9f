// SPDX-License-Identifier: BSD-3-Clause
// SLAM's loop search (docs/design/slam.md, "SLAM"): a closed keyframe's
// candidates through the cheapest checks first, their verification in
// waves, the graph's solve after an accepted loop, and the robustness
// study's injected false loops. The back end's side of RadarSlam.
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <limits>
#include <queue>
#include <random>
#include <utility>

#include "radargauss/slam/radar_slam.hpp"

namespace radargauss {

// Cheapest checks first: the descriptor's distance (close or not), each
// yaw's bird's-eye start against the graph (farther than the consistency
// bound plus verify_start_margin: refused), the best consistent start's
// overlap (below verify_min_overlap: refused), then the Gaussian
// match of the verify_budget best overlapping, in that order, as one thread
// would: the first that verifies is accepted and those after it are not
// matched. The matches run in waves of as many as there are threads
// (against the same graph, which changes only on acceptance), so that the
// accepted loop and every outcome are those of one thread; a wave may match
// some that one thread would not have reached.
void RadarSlam::SearchLoops(int query) {
  const auto start = std::chrono::steady_clock::now();
  if (last_loop_path_ >= 0.0 && options_.loop_spacing > 0.0 &&
      keyframes_[std::size_t(query)].path - last_loop_path_ < options_.loop_spacing) {
    return;
  }
  std::vector<int> eligible;  // far enough back along the path
  for (int c = 0; c < query && keyframes_[query].path - keyframes_[c].path >= options_.min_loop_path; ++c) {
    eligible.push_back(c);
  }
  std::vector<PlaceMatch> ranked = places_.Rank(places_.place(std::size_t(query)), eligible);
  const std::vector<double> paths = PathsThroughGraph(query);
  const LoopVerificationOptions& verification = options_.verification;
  std::vector<LoopCandidate> outcomes(ranked.size());
  std::vector<double> overlaps(ranked.size(), 0.0);
  std::vector<std::size_t> to_match;  // close, consistent and overlapping, best overlap first
  for (std::size_t i = 0; i < ranked.size(); ++i) {
    LoopCandidate& c = outcomes[i];
    c.query = query;
    c.candidate = ranked[i].candidate;
    c.distance = ranked[i].distance;
    c.yaw = ranked[i].yaws.front();
    char reason[80];
    if (!ranked[i].close) {
      std::snprintf(reason, sizeof(reason), "descriptor distance %.3f", ranked[i].distance);
      c.check.reason = reason;
      continue;
    }
    // The yaws whose start may end consistent with the graph, and their best overlap.
    const GraphPrior prior = PriorOf(c.candidate, query, paths);
    const std::vector<BirdsEyeStart> starts =
        BirdsEyeStarts(keyframes_[query].points, keyframes_[c.candidate].points, ranked[i].yaws, verification);
    std::vector<double> yaws;
    for (const BirdsEyeStart& start : starts) {
      if (!CorrectGraph(start.pose(), prior, verification, verification.start_margin, verification.start_margin_deg)
               .consistent) {
        continue;
      }
      yaws.push_back(start.yaw);
      overlaps[i] = std::max(overlaps[i], start.overlap);
    }
    c.check.overlap = overlaps[i];
    if (yaws.empty()) {
      const GraphCorrection off = CorrectGraph(starts.front().pose(), prior, verification);
      c.check.correction = off.translation;
      c.check.correction_deg = off.rotation_deg;
      std::snprintf(reason, sizeof(reason), "start inconsistent with the graph: %.1f m, %.1f deg", off.translation,
                    off.rotation_deg);
      c.check.reason = reason;
      continue;
    }
    ranked[i].yaws = std::move(yaws);
    if (overlaps[i] < verification.min_overlap) {
      std::snprintf(reason, sizeof(reason), "bird's-eye overlap %.2f", overlaps[i]);
      c.check.reason = reason;
      continue;
    }
    to_match.push_back(i);
  }
  std::stable_sort(to_match.begin(), to_match.end(),
                   [&](std::size_t a, std::size_t b) { return overlaps[a] > overlaps[b]; });
  const std::size_t budget = options_.verification.budget;
  for (std::size_t m = budget > 0 ? budget : to_match.size(); m < to_match.size(); ++m) {
    outcomes[to_match[m]].check.reason = "past the verification budget";
  }
  if (budget > 0 && to_match.size() > budget) to_match.resize(budget);
  const std::size_t wave = std::size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
  bool accepted = false;
  for (std::size_t m = 0; m < to_match.size(); m += wave) {
    const std::vector<std::size_t> members(to_match.begin() + std::ptrdiff_t(m),
                                           to_match.begin() + std::ptrdiff_t(std::min(to_match.size(), m + wave)));
    if (accepted) {
      for (const std::size_t i : members) outcomes[i].check.reason = "another candidate was accepted";
      continue;
    }
    const std::vector<LoopCandidate> results = VerifyWave(query, ranked, members, paths);
    for (std::size_t k = 0; k < members.size(); ++k) {
      LoopCandidate& c = outcomes[members[k]];
      if (accepted) {
        c.check.reason = "another candidate was accepted";
        continue;
      }
      c = results[k];
      if (c.check.accepted) {
        graph_.AddLoop(c.candidate, query, c.check.relative, c.check.sqrt_information);
        SolveAfterLoop(query, paths[std::size_t(c.candidate)]);
        last_loop_path_ = keyframes_[std::size_t(query)].path;
        accepted = true;
      }
    }
  }
  candidates_.insert(candidates_.end(), outcomes.begin(), outcomes.end());
  keyframes_[query].search_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (study_.rate > 0.0 && !eligible.empty()) InjectFalseLoop(query, eligible);
}

// The loop corrects the drift of the `path` metres it closes: the keyframes
// driven within that plus the margin move, the rest stays for Finish's
// whole solve (docs/design/slam.md, "SLAM").
void RadarSlam::SolveAfterLoop(int query, double path) {
  int first_free = 0;
  if (options_.local_solve_margin > 0.0) {
    const double reach = path + options_.local_solve_margin;
    first_free = query;
    while (first_free > 0 &&
           keyframes_[std::size_t(query)].path - keyframes_[std::size_t(first_free - 1)].path <= reach) {
      --first_free;
    }
  }
  graph_.Optimize(options_.graph, first_free);
  whole_solve_due_ = whole_solve_due_ || first_free > 0;
}

void RadarSlam::InjectFalseLoop(int query, const std::vector<int>& eligible) {
  if (std::uniform_real_distribution<double>(0.0, 1.0)(false_loops_) >= study_.rate) return;
  LoopCandidate loop;
  loop.query = query;
  loop.candidate = eligible[std::uniform_int_distribution<std::size_t>(0, eligible.size() - 1)(false_loops_)];
  loop.injected = true;
  loop.check.accepted = true;
  loop.check.reason = "injected false loop";
  Eigen::Matrix<double, 6, 1> weights;
  weights << Eigen::Vector3d::Constant(1.0 / options_.verification.translation_floor_std),
      Eigen::Vector3d::Constant(180.0 / M_PI / options_.verification.rotation_floor_std_deg);
  loop.check.sqrt_information = weights.asDiagonal();
  graph_.AddLoop(loop.candidate, query, SE3d(), loop.check.sqrt_information);
  graph_.Optimize(options_.graph);
  candidates_.push_back(loop);
}

std::vector<LoopCandidate> RadarSlam::VerifyWave(int query, const std::vector<PlaceMatch>& ranked,
                                                 const std::vector<std::size_t>& members,
                                                 const std::vector<double>& paths) {
  std::vector<int> indices;
  std::vector<const std::vector<RadarPoint>*> points;
  for (const std::size_t j : members) {
    indices.push_back(ranked[j].candidate);
    points.push_back(&keyframes_[ranked[j].candidate].points);
  }
  const std::vector<std::shared_ptr<const VerificationTarget>> targets =
      targets_.GetAll(indices, points, options_.verification);
  std::vector<LoopCandidate> results(members.size());
  tbb::parallel_for(std::size_t(0), members.size(), [&](std::size_t m) {
    const PlaceMatch& match = ranked[members[m]];
    results[m] = Verify(query, match, *targets[m], PriorOf(match.candidate, query, paths));
  });
  return results;
}

GraphPrior RadarSlam::PriorOf(int candidate, int query, const std::vector<double>& paths) const {
  return {graph_.poses()[candidate].Inverse() * graph_.poses()[query], paths[candidate]};
}

LoopCandidate RadarSlam::Verify(int query, const PlaceMatch& match, const VerificationTarget& target,
                                const GraphPrior& prior) const {
  LoopCandidate result;
  result.query = query;
  result.candidate = match.candidate;
  result.distance = match.distance;
  result.verified = true;
  for (const double yaw : match.yaws) {
    LoopCheck check = VerifyLoop(keyframes_[query].points, target, yaw, prior, options_.verification);
    if (check.accepted || yaw == match.yaws.front() || check.associated > result.check.associated) {
      result.check = std::move(check);
      result.yaw = yaw;
    }
    if (result.check.accepted) break;
  }
  return result;
}

std::vector<double> RadarSlam::PathsThroughGraph(int from) const {
  // Dijkstra over the keyframes: odometry edges weigh the metres driven, loop edges nothing.
  std::vector<std::vector<int>> loops(keyframes_.size());
  for (const PoseGraphEdge& edge : graph_.edges()) {
    if (!edge.loop) continue;
    loops[edge.from].push_back(edge.to);
    loops[edge.to].push_back(edge.from);
  }
  std::vector<double> distance(keyframes_.size(), std::numeric_limits<double>::infinity());
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  distance[from] = 0.0;
  queue.emplace(0.0, from);
  while (!queue.empty()) {
    const double d = queue.top().first;
    const int k = queue.top().second;
    queue.pop();
    if (d > distance[k]) continue;
    const auto relax = [&](int next, double weight) {
      if (d + weight < distance[next]) queue.emplace(distance[next] = d + weight, next);
    };
    if (k > 0) relax(k - 1, keyframes_[k].path - keyframes_[k - 1].path);
    if (k + 1 < int(keyframes_.size())) relax(k + 1, keyframes_[k + 1].path - keyframes_[k].path);
    for (const int next : loops[k]) relax(next, 0.0);
  }
  return distance;
}

}  // namespace radargauss
