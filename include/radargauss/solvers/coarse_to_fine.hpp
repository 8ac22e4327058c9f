// SPDX-License-Identifier: BSD-3-Clause
// The loop every single-scan solver shares (docs/design/solvers.md, "Coarse to
// fine" and "Association"): the stages of a match, the correspondences of
// each iteration, and the end of the match. A solver gives the step alone:
//
//   CoarseToFine match(scan, map, initial, options, priors);
//   return match.Run([&](const Stage& stage, int iteration) {
//     ... linearise match.correspondences() at match.pose(), solve, update match.pose() ...
//     return small_step ? StepResult::kConverged : StepResult::kContinue;
//   });
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "radargauss/solvers/correspondences.hpp"

namespace radargauss {

// One stage: a level of the MatchingMap with the points, gate and weight of
// eq. 2 it is matched with, its iteration limit and step tolerances.
struct Stage {
  std::size_t level = 0;
  bool finest = false;          // on the exact map
  bool full_cost = false;       // eq. 2 with the match's w: its last stage (else one that steers)
  ScanMatchingOptions options;  // the match's, with this stage's w_rcs
  int max_iterations = 0;
  double translation_tolerance = 0.0;  // m: a smaller step ends the stage ...
  double rotation_tolerance = 0.0;     // rad ... with a smaller rotation
  bool SmallStep(double translation, double rotation) const {
    return translation < translation_tolerance && rotation < rotation_tolerance;
  }
};

// What a solver's step made of an iteration: go on, the stage converged, or
// the match failed (its reason set).
enum class StepResult { kContinue, kConverged, kFailed };

class CoarseToFine {
 public:
  // The stages: the coarse levels, the exact map with the geometric term
  // alone (geometric_first, when re-associating), the exact map with eq. 2;
  // with w = 1 the last alone.
  CoarseToFine(const RadarScan& scan, const MatchingMap& map, const SE3d& initial, const ScanMatchingOptions& options,
               const ScanPriors& priors);
  // It keeps references: temporaries would not outlive it.
  CoarseToFine(const RadarScan&&, const MatchingMap&, const SE3d&, const ScanMatchingOptions&,
               const ScanPriors&) = delete;
  CoarseToFine(const RadarScan&, const MatchingMap&, const SE3d&, const ScanMatchingOptions&&,
               const ScanPriors&) = delete;
  CoarseToFine(const RadarScan&, const MatchingMap&, const SE3d&, const ScanMatchingOptions&,
               const ScanPriors&&) = delete;

  const std::vector<Stage>& stages() const { return stages_; }
  // The loop: per stage, per iteration, Associate and `step(stage,
  // iteration)`; a stage ends when its step converges or at its iteration
  // limit; the match ends converged when its last stage did.
  template <typename TakeStep>
  ScanMatchingResult Run(TakeStep&& step) {
    bool converged = false;
    for (const Stage& stage : stages_) {
      converged = false;
      for (int iteration = 1; iteration <= stage.max_iterations && !converged; ++iteration) {
        if (!Associate(stage, iteration)) return Failed();
        const StepResult result = step(stage, iteration);
        if (result == StepResult::kFailed) return Failed();
        converged = result == StepResult::kConverged;
      }
    }
    return Finish(converged);
  }
  // Iteration `iteration` of `stage` at pose(): its correspondences are made
  // at the first (the exact map's eq. 2 stage takes the geometric stage's
  // last ones with their RCS terms, if still within the re-association
  // thresholds), then kept while KeepsAssociation holds. Counts the
  // iteration; false with reason() when they cannot drive a step.
  bool Associate(const Stage& stage, int iteration);
  const Correspondences& correspondences() const { return correspondences_; }

  SE3d& pose() { return result_.pose; }
  const ScanPriors& priors() const { return priors_; }
  // Eq. 2 at `pose` on the current correspondences, when a step evaluated it:
  // Finish reuses it instead of evaluating it again.
  void RecordCost(const SE3d& pose, double cost) { evaluated_ = {true, pose, cost}; }
  void ForgetCost() { evaluated_.known = false; }
  // Why the match fails (a solver's own reason, or Associate's).
  void SetReason(std::string reason) { result_.reason = std::move(reason); }
  const std::string& reason() const { return result_.reason; }

  // The result: converged when `converged` (else the reason, or "iteration
  // limit reached"), the final association's counts, eq. 2 and the
  // information matrix at pose().
  ScanMatchingResult Finish(bool converged = false);
  ScanMatchingResult Failed() { return Finish(false); }

 private:
  struct EvaluatedCost {
    bool known = false;
    SE3d pose;
    double cost = 0.0;
  };
  void Begin(const Stage& stage);
  // The final association (the last one, when it was made on the exact map
  // within the re-association thresholds of the final pose, or when not
  // re-associating; otherwise a new one at the final pose), N_geo, N_rcs, the
  // cost of eq. 2 (the one recorded at the final pose on that association, if
  // any) and the information matrices.
  void FinishCounts(ScanMatchingResult& result) const;

  // The caller's, which outlive the match: nothing is copied per match.
  const RadarScan& scan_;
  const MatchingMap& map_;
  const SE3d initial_;
  const ScanMatchingOptions& options_;
  const ScanPriors& priors_;
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::vector<Stage> stages_;
  bool geometric_first_ = false;            // the exact map's geometric stage before eq. 2's
  bool reduce_ = false;                     // coarse levels match fewer points than the scan's
  std::vector<Eigen::Vector3d> positions_;  // the scan's, when reduce_
  RadarScan coarse_scan_;
  const RadarScan* stage_scan_ = nullptr;  // the current stage's points
  double gate_ = 0.0;                      // and gate
  Correspondences correspondences_;
  EvaluatedCost evaluated_;  // on correspondences_
  ScanMatchingResult result_;
};

}  // namespace radargauss
