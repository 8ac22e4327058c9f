// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/gauss_newton.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Cholesky>

#include "radargauss/core/conventions.hpp"
#include "radargauss/solvers/coarse_to_fine.hpp"
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

// The step check on the exact map (docs/design/solvers.md, "The own Gauss-Newton"):
// a step must not raise eq. 2 for its association; one that does is halved
// (at most max_step_halvings times). When the next iteration keeps the
// association, its system carries the cost at the new pose, so the check
// waits for it; otherwise eq. 2 is evaluated at once. A plain value, kept
// across the stages of a match.
struct StepCheck {
  struct Waiting {
    SE3d from;        // the pose the step was taken from
    Vector6 dx;       // the full step
    double cost = 0;  // eq. 2 at `from`
  };
  std::optional<Waiting> waiting;        // a step whose check waits for the next system
  const GaussianIndex* index = nullptr;  // the association the last waiting step was taken on
  SE3d associated_at;
  bool taken_back = false;  // a step on that association was taken back
  bool On(const Correspondences& c) const { return c.index == index && SamePose(c.pose, associated_at); }
};

// Halves dx from `from` (first by `scale`, `halvings` done) while eq. 2
// exceeds `cost`; sets the match's pose, records eq. 2 there when it
// evaluated it, returns the step taken.
Vector6 Backtrack(CoarseToFine& match, const Stage& stage, const SE3d& from, const Vector6& dx, double cost,
                  double scale, int halvings, int max_halvings) {
  SE3d next = Step(from, scale * dx);
  match.ForgetCost();
  for (; halvings < max_halvings; ++halvings) {
    const double next_cost = EvaluateCost(match.correspondences(), next, stage.options, match.priors());
    if (next_cost <= cost) {
      match.RecordCost(next, next_cost);
      break;
    }
    scale *= 0.5;
    next = Step(from, scale * dx);
  }
  match.pose() = next;
  return scale * dx;
}

// Takes dx on the exact map (eq. 2 at the match's pose: cost). Checked now
// when it ends the stage, follows a taken-back step on this association, or
// leaves the association; otherwise it waits for the next system.
Vector6 TakeChecked(CoarseToFine& match, const Stage& stage, StepCheck& check, bool same_association, const Vector6& dx,
                    double cost, bool last_iteration, int max_halvings) {
  const Correspondences& c = match.correspondences();
  const SE3d next = Step(match.pose(), dx);
  if (stage.SmallStep(dx.segment<3>(kTranslationOffset).norm(), dx.segment<3>(kRotationOffset).norm()) ||
      last_iteration || (same_association && check.taken_back) ||
      !KeepsAssociation(true, c.pose, next, stage.options)) {
    return Backtrack(match, stage, match.pose(), dx, cost, 1.0, 0, max_halvings);
  }
  check.waiting = StepCheck::Waiting{match.pose(), dx, cost};
  check.index = c.index;
  check.associated_at = c.pose;
  check.taken_back = false;
  match.pose() = next;
  return dx;
}

}  // namespace

GaussNewtonSolver::GaussNewtonSolver(const ScanMatchingOptions& options, const GaussNewtonOptions& gauss_newton)
    : options_(options), gauss_newton_(gauss_newton) {
  ValidateOptions(options_);
  if (gauss_newton_.max_step_halvings < 0) throw std::invalid_argument("max step halvings must be >= 0");
}

std::string GaussNewtonSolver::Name() const {
  return options_.jacobians == JacobianMode::kAnalytic ? "gn" : "gn-autodiff";
}

// The paper's loop per stage (docs/design/solvers.md, "Coarse to fine"): associate,
// linearise eq. 2, solve the 6x6 system, update the pose (checked on the
// exact map), stop on a small step.
ScanMatchingResult GaussNewtonSolver::Match(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                                            const ScanPriors& priors) const {
  CoarseToFine match(scan, map, initial, options_, priors);
  const int max_halvings = gauss_newton_.max_step_halvings;
  StepCheck check;
  return match.Run([&](const Stage& stage, int iteration) {
    const Correspondences& c = match.correspondences();
    // H = (1-w)/N_geo H_geo + w/N_rcs H_rcs plus the priors', likewise g (eq. 2).
    const CombinedSystem system =
        BuildCombinedSystem(c, match.pose(), stage.options, priors, gauss_newton_.loss_curvature);
    const bool same_association = check.On(c);
    const std::optional<StepCheck::Waiting> waiting = std::exchange(check.waiting, std::nullopt);
    Vector6 dx;
    if (waiting && same_association && system.cost > waiting->cost) {  // the last step raised eq. 2
      check.taken_back = true;
      dx = Backtrack(match, stage, waiting->from, waiting->dx, waiting->cost, 0.5, 1, max_halvings);
    } else {
      std::string reason;
      if (!SolveStep(system, gauss_newton_.loss_curvature, dx, reason)) {
        match.SetReason(reason);
        return StepResult::kFailed;
      }
      if (!stage.finest || max_halvings == 0) {  // plain steps: coarse levels only steer
        match.pose() = Step(match.pose(), dx);
      } else {
        dx = TakeChecked(match, stage, check, same_association, dx, system.cost, iteration == stage.max_iterations,
                         max_halvings);
      }
    }
    return stage.SmallStep(dx.segment<3>(kTranslationOffset).norm(), dx.segment<3>(kRotationOffset).norm())
               ? StepResult::kConverged
               : StepResult::kContinue;
  });
}

}  // namespace radargauss
