// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/ceres_solver.hpp"

#include <ceres/solver.h>

#include <stdexcept>

#include "radargauss/solvers/ceres_scan_problem.hpp"
#include "radargauss/solvers/coarse_to_fine.hpp"

namespace radargauss {

namespace {

// The pose held by the rotation (x y z w) and translation blocks.
SE3d PoseOfBlocks(const double* rotation, const double* translation) {
  return SE3d(SO3d(Eigen::Quaterniond(rotation[3], rotation[0], rotation[1], rotation[2])),
              Eigen::Vector3d(translation[0], translation[1], translation[2]));
}

// Ends a solve of the match's last stage on the exact map once the pose has
// left the re-association thresholds of the association made at
// `associated_at` (CeresSolverOptions::max_exact_inner_iterations), or once
// an accepted step is below the loop's step tolerances, as the own GN stops
// (`small_step`: the solve ended so).
class ExactMapStop final : public ceres::IterationCallback {
 public:
  ExactMapStop(const ScanMatchingOptions& options, const double* rotation, const double* translation)
      : options_(options), rotation_(rotation), translation_(translation) {}

  // Before each solve: the association's pose.
  void Start(const SE3d& associated_at) {
    associated_at_ = associated_at;
    small_step = false;
  }

  bool small_step = false;

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    const SE3d pose = PoseOfBlocks(rotation_, translation_);
    if (summary.iteration > 0 && summary.step_is_successful) {
      const SE3d step = previous_.Inverse() * pose;
      small_step = step.translation().norm() < options_.translation_tolerance &&
                   step.rotation().Log().norm() < options_.rotation_tolerance;
    }
    previous_ = pose;
    return !small_step && KeepsAssociation(true, associated_at_, pose, options_) ? ceres::SOLVER_CONTINUE
                                                                                 : ceres::SOLVER_TERMINATE_SUCCESSFULLY;
  }

 private:
  const ScanMatchingOptions& options_;
  const double* rotation_;  // x y z w, as Ceres updates it
  const double* translation_;
  SE3d associated_at_, previous_;
};

}  // namespace

CeresSolver::CeresSolver(const ScanMatchingOptions& options, const CeresSolverOptions& ceres_options)
    : options_(options), ceres_options_(ceres_options) {
  ValidateOptions(options_);
  if (ceres_options_.max_inner_iterations < 1 || ceres_options_.max_exact_inner_iterations < 1) {
    throw std::invalid_argument("Ceres iterations per solve must be >= 1");
  }
}

std::string CeresSolver::Name() const {
  std::string name = ceres_options_.dogleg ? "ceres-dogleg" : "ceres";
  if (options_.jacobians == JacobianMode::kAutoDiff) name += "-autodiff";
  return name;
}

ScanMatchingResult CeresSolver::Match(const RadarScan& scan, const MatchingMap& map, const SE3d& initial,
                                      const ScanPriors& priors) const {
  Eigen::Vector4d rotation = initial.rotation().quaternion().coeffs();
  Eigen::Vector3d translation = initial.translation();
  ceres::Solver::Options solver_options;
  solver_options.trust_region_strategy_type = ceres_options_.dogleg ? ceres::DOGLEG : ceres::LEVENBERG_MARQUARDT;
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;  // 6 unknowns, ~10^3 residuals
  solver_options.max_num_iterations = ceres_options_.max_inner_iterations;
  solver_options.num_threads = ceres_options_.threads;
  solver_options.logging_type = ceres::SILENT;
  solver_options.function_tolerance = ceres_options_.function_tolerance;
  solver_options.gradient_tolerance = ceres_options_.gradient_tolerance;
  solver_options.parameter_tolerance = ceres_options_.parameter_tolerance;
  CeresScanProblem problem(options_, priors, rotation.data(), translation.data(), ceres_options_.blocks,
                           ceres_options_.threads);

  ceres::Solver::Options exact_options = solver_options;
  exact_options.max_num_iterations = ceres_options_.max_exact_inner_iterations;
  exact_options.update_state_every_iteration = true;  // the callback reads the pose
  ExactMapStop stop(options_, rotation.data(), translation.data());
  exact_options.callbacks.push_back(&stop);
  // Per stage: associate, solve the association's problem, stop once the pose settles.
  CoarseToFine match(scan, map, initial, options_, priors);
  return match.Run([&](const Stage& stage, int) {
    const Correspondences& c = match.correspondences();
    problem.Update(c, stage.options.w_rcs);
    const SE3d before = match.pose();
    stop.Start(c.pose);
    ceres::Solver::Summary summary;
    ceres::Solve(stage.full_cost ? exact_options : solver_options, &problem.problem(), &summary);
    if (!summary.IsSolutionUsable() || !rotation.allFinite() || !translation.allFinite()) {
      match.SetReason("Ceres: " + summary.message);
      return StepResult::kFailed;
    }
    match.pose() = PoseOfBlocks(rotation.data(), translation.data());
    const SE3d step = before.Inverse() * match.pose();
    // Converged when the pose settled, or when Ceres converged (or took a
    // step below the tolerances) on an association the outer loop keeps:
    // the next solve would be the same problem from its own solution.
    // (stop.small_step: only the last stage's solves carry the callback)
    const bool settled = summary.termination_type == ceres::CONVERGENCE || stop.small_step;
    return stage.SmallStep(step.translation().norm(), step.rotation().Log().norm()) ||
                   (KeepsAssociation(stage.finest, c.pose, match.pose(), options_) && settled)
               ? StepResult::kConverged
               : StepResult::kContinue;
  });
}

}  // namespace radargauss
