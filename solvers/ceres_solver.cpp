#include "solvers/ceres_solver.hpp"

#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <memory>


#include "radargauss/lie/manifold.hpp"
#include "residuals/geometric_residual.hpp"
#include "residuals/rcs_residual.hpp"

namespace radargauss {

CeresSolver::CeresSolver(const ScanMatchingOptions& options, const CeresSolverOptions& ceres_options)
    : options_(options), ceres_options_(ceres_options) {
  ValidateOptions(options_);
}

std::string CeresSolver::Name() const {
  std::string name = ceres_options_.dogleg ? "ceres-dogleg" : "ceres";
  if (options_.jacobians == JacobianMode::kAutoDiff) name += "-autodiff";
  return name;
}

ScanMatchingResult CeresSolver::Match(const RadarScan& scan, const MatchingMap& map,
                                      const SE3d& initial) const {
  const bool analytic = options_.jacobians == JacobianMode::kAnalytic;
  const bool rotation_only = options_.rcs_translation == RcsTranslation::kRotationOnly;
  Eigen::Vector4d rotation = initial.rotation().quaternion().coeffs();
  Eigen::Vector3d translation = initial.translation();
  SO3Manifold so3;
  ceres::Solver::Options solver_options;
  solver_options.trust_region_strategy_type = ceres_options_.dogleg ? ceres::DOGLEG : ceres::LEVENBERG_MARQUARDT;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = ceres_options_.max_inner_iterations;
  solver_options.num_threads = ceres_options_.threads;
  solver_options.logging_type = ceres::SILENT;
  solver_options.function_tolerance = ceres_options_.function_tolerance;
  solver_options.gradient_tolerance = ceres_options_.gradient_tolerance;
  solver_options.parameter_tolerance = ceres_options_.parameter_tolerance;

  return RunCoarseToFine(scan, map, initial, options_, [&](const LevelStep& level, ScanMatchingResult& result) {
    const Correspondences& c = level.correspondences;
    const double w = level.options.w_rcs;
    ceres::Problem::Options problem_options;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_options.disable_all_safety_checks = true;  // blocks are built here, not by users
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // one loss per term, shared
    std::unique_ptr<ceres::LossFunction> geometric_loss, rcs_loss;
    ceres::Problem problem(problem_options);
    problem.AddParameterBlock(rotation.data(), 4, &so3);
    if (w < 1.0) {
      geometric_loss = std::make_unique<ceres::ScaledLoss>(MakeLoss(options_.geometric_loss),
                                                           (1.0 - w) / double(c.geometric.size()),
                                                           ceres::TAKE_OWNERSHIP);
      for (const GeometricTerm& term : c.geometric) {
        const Eigen::Vector3d& mean = c.index->Mean(term.gaussian);
        const Eigen::Matrix3d& LT = c.index->SqrtInformationT(term.gaussian);
        ceres::CostFunction* cost = analytic ? static_cast<ceres::CostFunction*>(
                                                   new GeometricCostFunction(term.point_radar, mean, LT))
                                             : GeometricResidual::Create(term.point_radar, mean, LT);
        problem.AddResidualBlock(cost, geometric_loss.get(), rotation.data(), translation.data());
      }
    }
    if (w > 0.0) {
      rcs_loss = std::make_unique<ceres::ScaledLoss>(MakeLoss(options_.rcs_loss), w / double(c.rcs.size()),
                                                     ceres::TAKE_OWNERSHIP);
      ceres::LossFunction* loss = rcs_loss.get();
      for (const RcsTerm& term : c.rcs) {
        if (rotation_only) {
          ceres::CostFunction* cost =
              analytic ? static_cast<ceres::CostFunction*>(new RcsRotationCostFunction(term, c.pose.translation()))
                       : RcsRotationResidual::Create(term, c.pose.translation());
          problem.AddResidualBlock(cost, loss, rotation.data());
        } else {
          ceres::CostFunction* cost = analytic ? static_cast<ceres::CostFunction*>(new RcsCostFunction(term))
                                               : RcsResidual::Create(term);
          problem.AddResidualBlock(cost, loss, rotation.data(), translation.data());
        }
      }
    }
    ceres::Solver::Summary summary;
    const SE3d before = result.pose;
    ceres::Solve(solver_options, &problem, &summary);
    if (!summary.IsSolutionUsable() || !rotation.allFinite() || !translation.allFinite()) {
      result.reason = "Ceres: " + summary.message;
      rotation = before.rotation().quaternion().coeffs();
      translation = before.translation();
      return StepOutcome::kFailed;
    }
    result.pose = SE3d(SO3d(Eigen::Quaterniond(rotation[3], rotation[0], rotation[1], rotation[2])), translation);
    const SE3d step = before.Inverse() * result.pose;
    const bool small =
        (result.pose.translation() - before.translation()).norm() < level.looseness * options_.translation_tolerance &&
        step.rotation().Log().norm() < level.looseness * options_.rotation_tolerance;
    // Converged when the pose settled, or, on a fixed association, when Ceres did.
    if (small || (!options_.reassociate && summary.termination_type == ceres::CONVERGENCE)) {
      return StepOutcome::kConverged;
    }
    return StepOutcome::kContinue;
  });
}

}  // namespace radargauss
