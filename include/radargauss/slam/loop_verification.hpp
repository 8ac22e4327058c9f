// SPDX-License-Identifier: BSD-3-Clause
// Verification of a loop candidate (docs/design/slam.md, "Loop verification"):
// the query keyframe's submap rotated by the descriptor's yaw and shifted in
// bird's eye view to the candidate's best overlap, then matched against the
// candidate's Gaussians by the multi-hypothesis Gauss-Newton; accepted on
// fitness, on the information matrix and on consistency with the graph.
#pragma once

#include <list>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/lie/se3.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/matching_map.hpp"
#include "radargauss/solvers/factory.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

// The match of a verification: multi-hypothesis Gauss-Newton, 2 m and 0.1 rad
// apart (the descriptor's yaw is a sector wide), eq. 2's geometric term.
inline MatchOptions LoopMatchOptions() {
  MatchOptions options;
  options.solver = SolverKind::kMultiHypothesis;
  options.hypotheses = {13, 2.0, 0.1};
  return options;
}

struct LoopVerificationOptions {
  double bev_cell = 1.0;                    // m: cells of the bird's-eye alignment
  double bev_search = 12.0;                 // m: translations tried around the keyframes' origins
  MatchOptions match = LoopMatchOptions();  // geometric: w_rcs 0
  GaussianMapOptions gaussians;             // the candidate submap's Gaussians (build-map's estimator)
  double min_associated = 0.5;              // share of the query's points within the gate
  double max_cost = 6.0;                    // eq. 2's f (mean squared Mahalanobis distance within the gate) at the end
  // The match's marginal stds (from N_geo times its information) may not exceed these.
  double max_translation_std = 0.2;  // m
  double max_rotation_std_deg = 1.0;
  // Consistency with the graph: the loop may move the query from its current
  // estimate by at most max(min_drift, drift * path) metres and
  // max(min_drift_deg, drift_deg * path) degrees, path the distance driven in
  // between along the graph (accepted loops crossed for free).
  double drift = 0.05;
  double min_drift = 5.0;   // m
  double drift_deg = 0.05;  // deg per m
  double min_drift_deg = 10.0;
  // Added to the match's covariance: what the submaps' own errors leave.
  double translation_floor_std = 0.1;  // m
  double rotation_floor_std_deg = 0.5;
  // Candidates made ready for verification (VerificationTarget) that a
  // search keeps, the last verified: each is built once while it stays.
  std::size_t kept_targets = 64;
  // Cheapest checks first (SLAM): a close candidate whose bird's-eye overlap
  // is below min_overlap is refused without its Gaussian match, and of the
  // rest the `budget` best overlapping are matched (0: all).
  double min_overlap = 0.4;
  std::size_t budget = 3;
  // A start (the descriptor's yaw, the bird's-eye shift) farther from the
  // graph's estimate than the consistency bound plus these cannot end
  // consistent: it is refused before its match.
  double start_margin = 10.0;  // m
  double start_margin_deg = 20.0;
};

// Where a match starts: the query turned by a descriptor's yaw and shifted
// to its best bird's-eye overlap with the candidate (AlignBirdsEye).
struct BirdsEyeStart {
  double yaw = 0.0;  // rad
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();
  double overlap = 0.0;  // share of the query's cells on the candidate's
  SE3d pose() const;     // candidate frame from query frame
};

// The start at each of `yaws`, in their order: the cheap check before a
// match (all overlaps 0 for a submap too small to verify).
std::vector<BirdsEyeStart> BirdsEyeStarts(const std::vector<RadarPoint>& query,
                                          const std::vector<RadarPoint>& candidate, const std::vector<double>& yaws,
                                          const LoopVerificationOptions& options);

// Its options (options.hpp), the match's and the submaps' Gaussians' among
// them; ValidateOptions throws std::invalid_argument naming the bad one.
const OptionTable<LoopVerificationOptions>& LoopVerificationOptionTable();
void ValidateOptions(const LoopVerificationOptions& options);

struct LoopCheck {
  bool accepted = false;
  std::string reason;       // why not; empty when accepted
  SE3d relative;            // the match: candidate frame from query frame
  double overlap = 0.0;     // share of the query's bird's-eye cells on the candidate's after the shift
  double associated = 0.0;  // share of the query's points
  double cost = 0.0;
  double translation_std = 0.0, rotation_std_deg = 0.0;
  double correction = 0.0, correction_deg = 0.0;                                       // against the graph's estimate
  Eigen::Matrix<double, 6, 6> sqrt_information = Eigen::Matrix<double, 6, 6>::Zero();  // of the relative-pose term
};

// The translation (x, y) that best overlaps the bird's-eye cells of `query`
// (already in the candidate's orientation) with those of `candidate`,
// searched on the cell grid within +/- search; and the share of query cells
// that overlap there.
std::pair<Eigen::Vector2d, double> AlignBirdsEye(const std::vector<Eigen::Vector3d>& query,
                                                 const std::vector<Eigen::Vector3d>& candidate, double cell,
                                                 double search);

// Where the graph has the query: its current candidate-from-query pose and
// the metres driven between them along the graph.
struct GraphPrior {
  SE3d expected;
  double path = 0.0;
};

// How far `relative` moves the query from the graph's estimate (m, deg), and
// whether that is within the consistency bound (drift, min_drift, ...) plus
// a margin.
struct GraphCorrection {
  double translation = 0.0, rotation_deg = 0.0;
  bool consistent = false;
};
GraphCorrection CorrectGraph(const SE3d& relative, const GraphPrior& prior, const LoopVerificationOptions& options,
                             double margin = 0.0, double margin_deg = 0.0);

// A candidate submap made ready for verification once: its points, the
// matching map of its Gaussians (none for a submap too small to verify) and
// the matcher, reused for every yaw and every query it is verified against.
class VerificationTarget {
 public:
  VerificationTarget(const std::vector<RadarPoint>& candidate, const LoopVerificationOptions& options);
  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  const MatchingMap* map() const { return map_.get(); }
  const ScanMatcher& matcher() const { return *matcher_; }

 private:
  std::vector<Eigen::Vector3d> points_;
  std::unique_ptr<const MatchingMap> map_;
  std::unique_ptr<const ScanMatcher> matcher_;
};

// The targets of the last `capacity` candidates verified, by their index
// (keyframe or map place): each built once while it stays.
class VerificationTargets {
 public:
  explicit VerificationTargets(std::size_t capacity) : capacity_(capacity) {}
  // The target of candidate `index`, built from `points` when not kept.
  std::shared_ptr<const VerificationTarget> Get(int index, const std::vector<RadarPoint>& points,
                                                const LoopVerificationOptions& options);
  // The targets of `indices` as Get in that order would leave them (the
  // same kept set and order), those not kept built in parallel (TBB).
  std::vector<std::shared_ptr<const VerificationTarget>> GetAll(
      const std::vector<int>& indices, const std::vector<const std::vector<RadarPoint>*>& points,
      const LoopVerificationOptions& options);
  std::size_t built() const { return built_; }

 private:
  std::size_t capacity_;
  std::list<std::pair<int, std::shared_ptr<const VerificationTarget>>> kept_;  // most recent first
  std::size_t built_ = 0;
};

// Checks the loop from `query` (points in its keyframe's frame) to
// `candidate` at the descriptor's `yaw`; without a prior (relocalisation)
// there is no consistency check.
LoopCheck VerifyLoop(const std::vector<RadarPoint>& query, const VerificationTarget& candidate, double yaw,
                     const std::optional<GraphPrior>& prior, const LoopVerificationOptions& options);
// The same, the target made for this check alone.
LoopCheck VerifyLoop(const std::vector<RadarPoint>& query, const std::vector<RadarPoint>& candidate, double yaw,
                     const std::optional<GraphPrior>& prior, const LoopVerificationOptions& options);

}  // namespace radargauss
