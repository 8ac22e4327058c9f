// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/ceres_scan_problem.hpp"

#include <ceres/loss_function.h>

#include <memory>

#include "radargauss/lie/manifold.hpp"
#include "radargauss/residuals/geometric_residual.hpp"
#include "radargauss/residuals/rcs_residual.hpp"
#include "radargauss/residuals/rotation_residual.hpp"
#include "radargauss/residuals/velocity_residual.hpp"
#include "radargauss/solvers/ceres_term_blocks.hpp"

namespace radargauss {

using internal::TermBlocks;

struct CeresScanProblem::Impl {
  Impl(const ScanMatchingOptions& options, const ScanPriors& priors, double* rotation, double* translation,
       CeresBlocks blocks, int threads)
      : options_(options),
        geometric_(problem_, options.geometric_loss, options.jacobians == JacobianMode::kAnalytic, blocks, threads,
                   {rotation, translation}),
        rcs_full_(problem_, options.rcs_loss, options.jacobians == JacobianMode::kAnalytic, blocks, threads,
                  {rotation, translation}),
        rcs_rotation_(problem_, options.rcs_loss, options.jacobians == JacobianMode::kAnalytic, blocks, threads,
                      {rotation}),
        problem_(ProblemOptions()) {
    problem_.AddParameterBlock(rotation, 4, &so3_);
    problem_.AddParameterBlock(translation, 3);
    if (priors.velocity && priors.velocity->weight > 0.0) {  // the same for every association
      velocity_cost_ = std::make_unique<VelocityCostFunction>(*priors.velocity);
      velocity_loss_ = std::make_unique<ceres::ScaledLoss>(nullptr, priors.velocity->weight, ceres::TAKE_OWNERSHIP);
      problem_.AddResidualBlock(velocity_cost_.get(), velocity_loss_.get(), translation);
    }
    if (priors.rotation && priors.rotation->weight > 0.0) {
      rotation_cost_ = std::make_unique<RotationCostFunction>(*priors.rotation);
      rotation_loss_ = std::make_unique<ceres::ScaledLoss>(nullptr, priors.rotation->weight, ceres::TAKE_OWNERSHIP);
      problem_.AddResidualBlock(rotation_cost_.get(), rotation_loss_.get(), rotation);
    }
  }

  void Update(const Correspondences& c, double w) {
    const std::size_t n_geometric = w < 1.0 ? c.geometric.size() : 0;
    if (n_geometric > 0) geometric_.SetWeight((1.0 - w) / double(n_geometric));
    for (std::size_t k = 0; k < n_geometric; ++k) {
      const GeometricTerm& term = c.geometric[k];
      geometric_.Set(k, term.point_radar, c.index->Mean(term.gaussian), c.index->SqrtInformationT(term.gaussian));
    }
    geometric_.Truncate(n_geometric);

    const std::size_t n_rcs = w > 0.0 ? c.rcs.size() : 0;
    if (n_rcs > 0) {
      rcs_full_.SetWeight(w / double(n_rcs));
      rcs_rotation_.SetWeight(w / double(n_rcs));
    }
    // Rotation-only: the RCS residuals take the rotation block only, the
    // translation a constant of the association.
    const bool rotation_only = options_.rcs_translation == RcsTranslation::kRotationOnly;
    for (std::size_t k = 0; k < n_rcs; ++k) {
      if (rotation_only) {
        rcs_rotation_.Set(k, c.rcs[k], c.pose.translation());
      } else {
        rcs_full_.Set(k, c.rcs[k]);
      }
    }
    rcs_rotation_.Truncate(rotation_only ? n_rcs : 0);
    rcs_full_.Truncate(rotation_only ? 0 : n_rcs);
  }

  static ceres::Problem::Options ProblemOptions() {
    ceres::Problem::Options options;
    options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // the term blocks own them
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // one wrapper per kind of term, members
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.disable_all_safety_checks = true;  // blocks are built here, not by users
    return options;
  }

  ScanMatchingOptions options_;
  SO3Manifold so3_;
  TermBlocks<GeometricResidual, GeometricCostFunction> geometric_;
  TermBlocks<RcsResidual, RcsCostFunction> rcs_full_;
  TermBlocks<RcsRotationResidual, RcsRotationCostFunction> rcs_rotation_;
  std::unique_ptr<ceres::CostFunction> velocity_cost_;  // the velocity term, when set
  std::unique_ptr<ceres::LossFunction> velocity_loss_;
  std::unique_ptr<ceres::CostFunction> rotation_cost_;  // the rotation term, when set
  std::unique_ptr<ceres::LossFunction> rotation_loss_;
  ceres::Problem problem_;  // last: destroyed before what it refers to
};

CeresScanProblem::CeresScanProblem(const ScanMatchingOptions& options, const ScanPriors& priors, double* rotation,
                                   double* translation, CeresBlocks blocks, int threads)
    : impl_(std::make_unique<Impl>(options, priors, rotation, translation, blocks, threads)) {}
CeresScanProblem::~CeresScanProblem() = default;
void CeresScanProblem::Update(const Correspondences& correspondences, double w_rcs) {
  impl_->Update(correspondences, w_rcs);
}
ceres::Problem& CeresScanProblem::problem() { return impl_->problem_; }

}  // namespace radargauss
