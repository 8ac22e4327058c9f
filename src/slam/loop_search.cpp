// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/slam/loop_search.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <utility>

namespace radargauss {

LoopSearch::LoopSearch(const SlamOptions& options)
    : options_(options), places_(options.place_recognition), targets_(options.verification.kept_targets) {}

// Cheapest checks first: the descriptor's distance (close or not), each
// yaw's bird's-eye start against the graph (farther than the consistency
// bound plus verify_start_margin: refused), the best consistent start's
// overlap (below verify_min_overlap: refused), then the Gaussian
// match of the verify_budget best overlapping, in that order, as one thread
// would: the first that verifies is accepted and those after it are not
// matched. The matches run in waves of as many as there are threads
// (against the same graph: the search reads it, the caller adds the
// accepted loop), so that the accepted loop and every outcome are those of
// one thread; a wave may match some that one thread would not have reached.
LoopSearchResult LoopSearch::Search(int query, const KeyframeGraph& graph, const std::vector<bool>* candidates) {
  const std::vector<Keyframe>& keyframes = graph.keyframes();
  LoopSearchResult result;
  if (last_loop_path_ >= 0.0 && options_.loop_spacing > 0.0 &&
      keyframes[std::size_t(query)].path - last_loop_path_ < options_.loop_spacing) {
    return result;
  }
  result.searched = true;
  std::vector<int>& eligible = result.eligible;  // far enough back along the path
  for (int c = 0; c < query && keyframes[query].path - keyframes[c].path >= options_.min_loop_path; ++c) {
    if (!candidates || (*candidates)[std::size_t(c)]) eligible.push_back(c);
  }
  std::vector<PlaceMatch> ranked = places_.Rank(places_.place(std::size_t(query)), eligible);
  const std::vector<double> paths = graph.PathsFrom(query);
  const LoopVerificationOptions& verification = options_.verification;
  std::vector<LoopCandidate>& outcomes = result.outcomes;
  outcomes.resize(ranked.size());
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
    const GraphPrior prior = graph.PriorOf(c.candidate, query, paths);
    const std::vector<BirdsEyeStart> starts =
        BirdsEyeStarts(keyframes[query].points, keyframes[c.candidate].points, ranked[i].yaws, verification);
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
    const std::vector<LoopCandidate> results = VerifyWave(query, graph, ranked, members, paths);
    for (std::size_t k = 0; k < members.size(); ++k) {
      LoopCandidate& c = outcomes[members[k]];
      if (accepted) {
        c.check.reason = "another candidate was accepted";
        continue;
      }
      c = results[k];
      if (c.check.accepted) {
        result.accepted = members[k];
        result.path = paths[std::size_t(c.candidate)];
        last_loop_path_ = keyframes[std::size_t(query)].path;
        accepted = true;
      }
    }
  }
  candidates_.insert(candidates_.end(), outcomes.begin(), outcomes.end());
  return result;
}

std::optional<LoopCandidate> FalseLoops::Inject(int query, const std::vector<int>& eligible, KeyframeGraph& graph) {
  if (study_.rate <= 0.0 || eligible.empty()) return std::nullopt;
  if (std::uniform_real_distribution<double>(0.0, 1.0)(random_) >= study_.rate) return std::nullopt;
  LoopCandidate loop;
  loop.query = query;
  loop.candidate = eligible[std::uniform_int_distribution<std::size_t>(0, eligible.size() - 1)(random_)];
  loop.injected = true;
  loop.check.accepted = true;
  loop.check.reason = "injected false loop";
  Eigen::Matrix<double, 6, 1> weights;
  weights << Eigen::Vector3d::Constant(1.0 / verification_.translation_floor_std),
      Eigen::Vector3d::Constant(180.0 / M_PI / verification_.rotation_floor_std_deg);
  loop.check.sqrt_information = weights.asDiagonal();
  graph.AddLoopAndSolve(loop.candidate, query, SE3d(), loop.check.sqrt_information);
  return loop;
}

std::vector<LoopCandidate> LoopSearch::VerifyWave(int query, const KeyframeGraph& graph,
                                                  const std::vector<PlaceMatch>& ranked,
                                                  const std::vector<std::size_t>& members,
                                                  const std::vector<double>& paths) {
  const std::vector<Keyframe>& keyframes = graph.keyframes();
  std::vector<int> indices;
  std::vector<const std::vector<RadarPoint>*> points;
  for (const std::size_t j : members) {
    indices.push_back(ranked[j].candidate);
    points.push_back(&keyframes[ranked[j].candidate].points);
  }
  const std::vector<std::shared_ptr<const VerificationTarget>> targets =
      targets_.GetAll(indices, points, options_.verification);
  std::vector<LoopCandidate> results(members.size());
  tbb::parallel_for(std::size_t(0), members.size(), [&](std::size_t m) {
    const PlaceMatch& match = ranked[members[m]];
    results[m] = Verify(query, graph, match, *targets[m], graph.PriorOf(match.candidate, query, paths));
  });
  return results;
}

LoopCandidate LoopSearch::Verify(int query, const KeyframeGraph& graph, const PlaceMatch& match,
                                 const VerificationTarget& target, const GraphPrior& prior) const {
  LoopCandidate result;
  result.query = query;
  result.candidate = match.candidate;
  result.distance = match.distance;
  result.verified = true;
  for (const double yaw : match.yaws) {
    LoopCheck check = VerifyLoop(graph.keyframes()[query].points, target, yaw, prior, options_.verification);
    if (check.accepted || yaw == match.yaws.front() || check.associated > result.check.associated) {
      result.check = std::move(check);
      result.yaw = yaw;
    }
    if (result.check.accepted) break;
  }
  return result;
}

}  // namespace radargauss
