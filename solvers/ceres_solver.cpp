#include "solvers/ceres_solver.hpp"

#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "radargauss/lie/manifold.hpp"
#include "residuals/geometric_residual.hpp"
#include "residuals/rcs_residual.hpp"

namespace radargauss {

namespace {

// Terms [begin, end) of one kind as one residual block: term k's residuals
// and Jacobian rows sit at k times one term's (Ceres's Jacobians are
// row-major), so the block evaluates the terms' own cost functions side by
// side. Ceres applies a block's loss to the block's squared norm, which is
// the sum of the terms' losses only for a (scaled) trivial loss: used there
// alone (TermBlocks), where it pays Ceres's per-block work (evaluator loop,
// manifold product, loss correction, checks) once per block of terms.
class TermRangeCost final : public ceres::CostFunction {
 public:
  explicit TermRangeCost(const ceres::CostFunction& term) : term_residuals_(term.num_residuals()) {
    if (term.parameter_block_sizes().size() > kMaxParameterBlocks) {
      throw std::logic_error("TermRangeCost: a term with more than two parameter blocks");
    }
    *mutable_parameter_block_sizes() = term.parameter_block_sizes();
  }

  void Reset(std::vector<const ceres::CostFunction*> terms) {
    terms_ = std::move(terms);
    set_num_residuals(term_residuals_ * int(terms_.size()));
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const std::vector<std::int32_t>& sizes = parameter_block_sizes();
    double* term_jacobians[kMaxParameterBlocks];
    for (std::size_t k = 0; k < terms_.size(); ++k) {
      for (std::size_t b = 0; b < sizes.size(); ++b) {
        term_jacobians[b] = jacobians != nullptr && jacobians[b] != nullptr
                                ? jacobians[b] + k * std::size_t(term_residuals_ * sizes[b])
                                : nullptr;
      }
      if (!terms_[k]->Evaluate(parameters, residuals + k * term_residuals_, jacobians ? term_jacobians : nullptr)) {
        return false;
      }
    }
    return true;
  }

 private:
  static constexpr std::size_t kMaxParameterBlocks = 2;  // rotation, translation
  int term_residuals_;
  std::vector<const ceres::CostFunction*> terms_;
};

// The residual blocks of one kind of term, kept across associations: cost
// function k holds term k of the current association. A new association
// re-targets the cost functions it keeps (Reset on the functor or the
// analytic twin) and adds or removes blocks only for the change in count,
// so that Ceres's per-block set-up is paid about once per match instead of
// once per association. Analytic terms under a trivial loss sit in residual
// blocks of kTermsPerBlock (TermRangeCost).
template <typename Functor, typename AnalyticCost>
class TermBlocks {
 public:
  TermBlocks(ceres::Problem& problem, ceres::LossFunction* loss, bool analytic, bool trivial_loss,
             std::vector<double*> parameters)
      : problem_(problem),
        loss_(loss),
        analytic_(analytic),
        ranged_(analytic && trivial_loss),
        parameters_(std::move(parameters)) {}

  // Term k is the one made from `args` (and, unless ranged, its block is in the problem).
  template <typename... Args>
  void Set(std::size_t k, const Args&... args) {
    if (k == blocks_.size()) {
      Block block;
      if (analytic_) {
        block.analytic = new AnalyticCost(args...);
        block.cost.reset(block.analytic);
      } else {
        block.functor = new Functor(args...);
        block.cost = std::make_unique<typename Functor::AutoDiff>(block.functor);
      }
      blocks_.push_back(std::move(block));
    } else if (analytic_) {
      blocks_[k].analytic->Reset(args...);
    } else {
      blocks_[k].functor->Reset(args...);
    }
    Block& block = blocks_[k];
    if (!ranged_ && block.id == nullptr) {
      block.id = problem_.AddResidualBlock(block.cost.get(), loss_, parameters_.data(), int(parameters_.size()));
    }
  }

  // Makes terms [0, count) the problem's terms of this kind (blocks of
  // terms k >= count are taken out and kept for later associations).
  void Truncate(std::size_t count) {
    if (ranged_) {
      Range(count);
      return;
    }
    for (std::size_t k = count; k < blocks_.size(); ++k) {
      if (blocks_[k].id == nullptr) continue;
      problem_.RemoveResidualBlock(blocks_[k].id);
      blocks_[k].id = nullptr;
    }
  }

 private:
  // The range blocks over terms [0, count), made afresh (a handful per match).
  void Range(std::size_t count) {
    for (const ceres::ResidualBlockId id : range_ids_) problem_.RemoveResidualBlock(id);
    range_ids_.clear();
    for (std::size_t begin = 0, r = 0; begin < count; begin += CeresScanProblem::kTermsPerBlock, ++r) {
      const std::size_t end = std::min(count, begin + CeresScanProblem::kTermsPerBlock);
      if (r == ranges_.size()) ranges_.push_back(std::make_unique<TermRangeCost>(*blocks_[0].cost));
      std::vector<const ceres::CostFunction*> terms;
      terms.reserve(end - begin);
      for (std::size_t k = begin; k < end; ++k) terms.push_back(blocks_[k].cost.get());
      ranges_[r]->Reset(std::move(terms));
      range_ids_.push_back(
          problem_.AddResidualBlock(ranges_[r].get(), loss_, parameters_.data(), int(parameters_.size())));
    }
  }

  struct Block {
    std::unique_ptr<ceres::CostFunction> cost;
    Functor* functor = nullptr;         // autodiff: the functor `cost` owns
    AnalyticCost* analytic = nullptr;   // analytic: `cost` itself
    ceres::ResidualBlockId id = nullptr;  // null while not in the problem (always when ranged)
  };
  ceres::Problem& problem_;
  ceres::LossFunction* loss_;
  bool analytic_;
  bool ranged_;
  std::vector<double*> parameters_;
  std::vector<Block> blocks_;
  std::vector<std::unique_ptr<TermRangeCost>> ranges_;
  std::vector<ceres::ResidualBlockId> range_ids_;
};

}  // namespace

struct CeresScanProblem::Impl {
  Impl(const ScanMatchingOptions& options, double* rotation, double* translation)
      : options_(options),
        geometric_(problem_, &geometric_loss_, options.jacobians == JacobianMode::kAnalytic,
                   options.geometric_loss.type == LossType::kTrivial, {rotation, translation}),
        rcs_full_(problem_, &rcs_loss_, options.jacobians == JacobianMode::kAnalytic,
                  options.rcs_loss.type == LossType::kTrivial, {rotation, translation}),
        rcs_rotation_(problem_, &rcs_loss_, options.jacobians == JacobianMode::kAnalytic,
                      options.rcs_loss.type == LossType::kTrivial, {rotation}),
        problem_(ProblemOptions()) {
    problem_.AddParameterBlock(rotation, 4, &so3_);
    problem_.AddParameterBlock(translation, 3);
  }

  void Update(const Correspondences& c, double w) {
    const std::size_t n_geometric = w < 1.0 ? c.geometric.size() : 0;
    if (n_geometric > 0) {
      geometric_loss_.Reset(new ceres::ScaledLoss(MakeLoss(options_.geometric_loss), (1.0 - w) / double(n_geometric),
                                                  ceres::TAKE_OWNERSHIP),
                            ceres::TAKE_OWNERSHIP);
    }
    for (std::size_t k = 0; k < n_geometric; ++k) {
      const GeometricTerm& term = c.geometric[k];
      geometric_.Set(k, term.point_radar, c.index->Mean(term.gaussian), c.index->SqrtInformationT(term.gaussian));
    }
    geometric_.Truncate(n_geometric);

    const std::size_t n_rcs = w > 0.0 ? c.rcs.size() : 0;
    if (n_rcs > 0) {
      rcs_loss_.Reset(new ceres::ScaledLoss(MakeLoss(options_.rcs_loss), w / double(n_rcs), ceres::TAKE_OWNERSHIP),
                      ceres::TAKE_OWNERSHIP);
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
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // one wrapper per term, members
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.disable_all_safety_checks = true;  // blocks are built here, not by users
    return options;
  }

  ScanMatchingOptions options_;
  SO3Manifold so3_;
  ceres::LossFunctionWrapper geometric_loss_{nullptr, ceres::TAKE_OWNERSHIP};
  ceres::LossFunctionWrapper rcs_loss_{nullptr, ceres::TAKE_OWNERSHIP};
  TermBlocks<GeometricResidual, GeometricCostFunction> geometric_;
  TermBlocks<RcsResidual, RcsCostFunction> rcs_full_;
  TermBlocks<RcsRotationResidual, RcsRotationCostFunction> rcs_rotation_;
  ceres::Problem problem_;  // last: destroyed before what it refers to
};

CeresScanProblem::CeresScanProblem(const ScanMatchingOptions& options, double* rotation, double* translation)
    : impl_(std::make_unique<Impl>(options, rotation, translation)) {}
CeresScanProblem::~CeresScanProblem() = default;
void CeresScanProblem::Update(const Correspondences& correspondences, double w_rcs) {
  impl_->Update(correspondences, w_rcs);
}
ceres::Problem& CeresScanProblem::problem() { return impl_->problem_; }

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
  CeresScanProblem problem(options_, rotation.data(), translation.data());

  return RunCoarseToFine(scan, map, initial, options_, [&](const LevelStep& level, ScanMatchingResult& result) {
    const Correspondences& c = level.correspondences;
    problem.Update(c, level.options.w_rcs);
    ceres::Solver::Summary summary;
    const SE3d before = result.pose;
    ceres::Solve(solver_options, &problem.problem(), &summary);
    if (!summary.IsSolutionUsable() || !rotation.allFinite() || !translation.allFinite()) {
      result.reason = "Ceres: " + summary.message;
      rotation = before.rotation().quaternion().coeffs();
      translation = before.translation();
      return StepOutcome::kFailed;
    }
    result.pose = SE3d(SO3d(Eigen::Quaterniond(rotation[3], rotation[0], rotation[1], rotation[2])), translation);
    const SE3d step = before.Inverse() * result.pose;
    const bool small = level.SmallStep(step.translation().norm(), step.rotation().Log().norm());
    // Converged when the pose settled, or when Ceres converged on an
    // association the outer loop keeps: the next solve would be the same
    // problem from its own solution.
    if (small || (KeepsAssociation(level.finest, c.pose, result.pose, options_) &&
                  summary.termination_type == ceres::CONVERGENCE)) {
      return StepOutcome::kConverged;
    }
    return StepOutcome::kContinue;
  });
}

}  // namespace radargauss
