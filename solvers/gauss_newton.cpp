// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/gauss_newton.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>

#include "radargauss/conventions.hpp"
#include "radargauss/solvers/normal_equations.hpp"

namespace radargauss {

namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;

// The update of conventions.hpp: t += dt (world), R = R Exp(dphi) (radar frame).
SE3d Step(const SE3d& pose, const Vector6& dx) {
  return SE3d(pose.rotation() * SO3d::Exp(dx.segment<3>(kRotationOffset)),
              pose.translation() + dx.segment<3>(kTranslationOffset));
}

bool PositiveDefinite(const Eigen::LDLT<Eigen::Matrix<double, 6, 6>>& ldlt) {
  const Vector6 pivots = ldlt.vectorD();
  return ldlt.info() == Eigen::Success && pivots.minCoeff() > 1e-10 * std::max(1e-300, pivots.maxCoeff());
}

// H dx = -g by LDLT, with the losses' curvature in H when asked and positive
// definite, else IRLS; false with a reason when degenerate.
bool SolveStep(const CombinedSystem& system, bool loss_curvature, Vector6& dx, std::string& reason) {
  Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt;
  if (!loss_curvature || !PositiveDefinite(ldlt.compute(system.H + system.loss_curvature))) {
    if (!PositiveDefinite(ldlt.compute(system.H))) {
      reason = "degenerate normal equations (too few or ill-placed residuals)";
      return false;
    }
  }
  dx = ldlt.solve(-system.g);
  if (!dx.allFinite()) {
    reason = "non-finite update";
    return false;
  }
  return true;
}

// The step check on the exact map: a step must not raise eq. 2 for its
// association; one that does is halved (at most max_halvings times). When
// the next iteration keeps the association, its system carries the cost at
// the new pose, so the check waits for it (no extra pass over the
// residuals); otherwise eq. 2 is evaluated at once.
class StepCheck {
 public:
  explicit StepCheck(int max_halvings) : max_halvings_(max_halvings) {}

  // First in every iteration, with eq. 2 at the current pose: a waiting step
  // on this association that raised it is taken back and halved; returns
  // the step taken instead then.
  std::optional<Vector6> TakeBackRaisingStep(const LevelStep& level, double cost, SE3d& pose) {
    const Correspondences& c = level.correspondences;
    same_association_ = c.index == index_ && SamePose(c.pose, associated_at_);
    if (!pending_) return std::nullopt;
    pending_ = false;
    if (!same_association_ || !(cost > cost_)) return std::nullopt;
    taken_back_ = true;
    return Backtrack(level, from_, dx_, cost_, 0.5, 1, pose);
  }

  // Takes dx from `pose` (eq. 2 there: cost). Checked now when it converges,
  // is the level's last, follows a taken-back step on this association, or
  // leaves the association; otherwise it waits. Returns the step taken.
  Vector6 Take(const LevelStep& level, const Vector6& dx, double cost, const ScanMatchingOptions& options,
               SE3d& pose) {
    const Correspondences& c = level.correspondences;
    const bool small = level.SmallStep(dx.segment<3>(kTranslationOffset).norm(), dx.segment<3>(kRotationOffset).norm());
    const SE3d next = Step(pose, dx);
    if (small || level.last_iteration || (same_association_ && taken_back_) ||
        !KeepsAssociation(true, c.pose, next, options)) {
      return Backtrack(level, pose, dx, cost, 1.0, 0, pose);
    }
    pending_ = true;
    from_ = pose;
    dx_ = dx;
    cost_ = cost;
    index_ = c.index;
    associated_at_ = c.pose;
    taken_back_ = false;
    pose = next;
    return dx;
  }

 private:
  // Halves dx from `from` (first by `scale`) while eq. 2 exceeds `cost`; sets
  // `pose`, records eq. 2 there when it evaluated it, returns the step taken.
  Vector6 Backtrack(const LevelStep& level, SE3d from, const Vector6& dx, double cost, double scale, int halvings,
                    SE3d& pose) const {
    SE3d next = Step(from, scale * dx);
    level.evaluated->known = false;
    for (; halvings < max_halvings_; ++halvings) {
      const double next_cost = EvaluateCost(level.correspondences, next, level.options);
      if (next_cost <= cost) {
        *level.evaluated = {true, next, next_cost};
        break;
      }
      scale *= 0.5;
      next = Step(from, scale * dx);
    }
    pose = next;
    return scale * dx;
  }

  int max_halvings_;
  bool pending_ = false;                // a step waits for its check
  SE3d from_;                           // the pose it was taken from
  Vector6 dx_ = Vector6::Zero();        // the full step
  double cost_ = 0.0;                   // eq. 2 at from_
  const GaussianIndex* index_ = nullptr;  // the association it was taken on
  SE3d associated_at_;
  bool taken_back_ = false;             // a step on that association was taken back
  bool same_association_ = false;       // this iteration's association is that one
};

}  // namespace

GaussNewtonSolver::GaussNewtonSolver(const ScanMatchingOptions& options, const GaussNewtonOptions& gauss_newton)
    : options_(options), gauss_newton_(gauss_newton) {
  ValidateOptions(options_);
  if (gauss_newton_.max_step_halvings < 0) throw std::invalid_argument("max step halvings must be >= 0");
}

std::string GaussNewtonSolver::Name() const {
  return options_.jacobians == JacobianMode::kAnalytic ? "gn" : "gn-autodiff";
}

// The paper's loop, per iteration of RunCoarseToFine (which associates):
// linearise eq. 2, solve the 6x6 system, step (checked on the exact map).
ScanMatchingResult GaussNewtonSolver::Match(const RadarScan& scan, const MatchingMap& map,
                                            const SE3d& initial) const {
  StepCheck check(gauss_newton_.max_step_halvings);
  return RunCoarseToFine(scan, map, initial, options_, [&, this](const LevelStep& level, ScanMatchingResult& result) {
    const auto outcome = [&](const Vector6& step) {
      return level.SmallStep(step.segment<3>(kTranslationOffset).norm(), step.segment<3>(kRotationOffset).norm())
                 ? StepOutcome::kConverged
                 : StepOutcome::kContinue;
    };
    // Eq. 2: H = (1-w)/N_geo H_geo + w/N_rcs H_rcs, likewise g.
    const CombinedSystem system =
        BuildCombinedSystem(level.correspondences, result.pose, level.options, gauss_newton_.loss_curvature);
    if (const std::optional<Vector6> step = check.TakeBackRaisingStep(level, system.cost, result.pose)) {
      return outcome(*step);
    }
    Vector6 dx;
    if (!SolveStep(system, gauss_newton_.loss_curvature, dx, result.reason)) return StepOutcome::kFailed;
    if (!level.finest || gauss_newton_.max_step_halvings == 0) {  // plain steps: coarse levels only steer
      result.pose = Step(result.pose, dx);
      return outcome(dx);
    }
    return outcome(check.Take(level, dx, system.cost, options_, result.pose));
  });
}

}  // namespace radargauss
