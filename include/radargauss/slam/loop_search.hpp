// SPDX-License-Identifier: BSD-3-Clause
// SLAM's loop search (docs/design/slam.md, "SLAM"): a place per closed
// keyframe, and for each its candidates through the cheapest checks first,
// then verified in waves against kept verification targets. The search
// reads the keyframe graph and returns its verdicts; the accepted loop goes
// into the graph by its caller. A study of robustness (FalseLoops) injects
// false loops beside it.
#pragma once

#include <cstddef>
#include <optional>
#include <random>
#include <vector>

#include "radargauss/slam/keyframe_graph.hpp"
#include "radargauss/slam/loop_verification.hpp"
#include "radargauss/slam/place_recognition.hpp"
#include "radargauss/slam/slam_options.hpp"

namespace radargauss {

// A compared pair: the descriptor's verdict, then the verification's.
struct LoopCandidate {
  int query = 0, candidate = 0;  // keyframes
  double distance = 1.0;         // the descriptor's
  double yaw = 0.0;              // rad: the descriptor's, of the query in the candidate
  bool verified = false;         // passed to verification
  bool injected = false;         // a false loop of FalseLoopStudy, not a candidate
  LoopCheck check;               // check.accepted: in the graph
};

// What one keyframe's search found.
struct LoopSearchResult {
  bool searched = false;                // false: within loop_spacing of the last accepted loop
  std::vector<int> eligible;            // the keyframes far enough back along the path
  std::vector<LoopCandidate> outcomes;  // one per ranked candidate
  std::optional<std::size_t> accepted;  // its index in outcomes
  double path = 0.0;                    // m from the accepted loop's candidate to the query through the graph
};

class LoopSearch {
 public:
  explicit LoopSearch(const SlamOptions& options);

  // The place of the graph's last keyframe, from its submap.
  void AddPlace(const std::vector<RadarPoint>& submap) { places_.Add(places_.Describe(submap)); }
  // The loops of keyframe `query` (the last with a place), as one thread
  // would find them whatever the threads; the outcomes are kept
  // (candidates()). `candidates`: per keyframe before the query, whether it
  // may be one (null: every one).
  LoopSearchResult Search(int query, const KeyframeGraph& graph, const std::vector<bool>* candidates = nullptr);
  // Every compared pair so far, injected false loops among them.
  const std::vector<LoopCandidate>& candidates() const { return candidates_; }
  void Record(const LoopCandidate& candidate) { candidates_.push_back(candidate); }
  std::size_t verification_targets_built() const { return targets_.built(); }

 private:
  // The Gaussian matches of ranked[members], in parallel.
  std::vector<LoopCandidate> VerifyWave(int query, const KeyframeGraph& graph, const std::vector<PlaceMatch>& ranked,
                                        const std::vector<std::size_t>& members, const std::vector<double>& paths);
  LoopCandidate Verify(int query, const KeyframeGraph& graph, const PlaceMatch& match, const VerificationTarget& target,
                       const GraphPrior& prior) const;

  SlamOptions options_;
  PlaceDatabase places_;         // a place per closed keyframe
  VerificationTargets targets_;  // the last verified keyframes' verification maps
  std::vector<LoopCandidate> candidates_;
  double last_loop_path_ = -1.0;  // m driven to the last accepted loop's query (-1: none)
};

// FalseLoopStudy: after a keyframe's search, with probability `rate`, a
// false loop to an eligible keyframe at random goes into the graph.
class FalseLoops {
 public:
  FalseLoops(const FalseLoopStudy& study, const LoopVerificationOptions& verification)
      : study_(study), verification_(verification), random_(study.seed) {}
  bool active() const { return study_.rate > 0.0; }
  // The injected loop, when the draw gives one (already in `graph`).
  std::optional<LoopCandidate> Inject(int query, const std::vector<int>& eligible, KeyframeGraph& graph);

 private:
  FalseLoopStudy study_;
  LoopVerificationOptions verification_;
  std::mt19937 random_;
};

}  // namespace radargauss
