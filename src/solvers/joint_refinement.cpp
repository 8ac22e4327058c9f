// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/joint_refinement.hpp"

#include <ceres/normal_prior.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>

#include "radargauss/core/error.hpp"
#include "radargauss/lie/manifold.hpp"
#include "radargauss/residuals/geometric_residual.hpp"
#include "radargauss/residuals/rcs_residual.hpp"
#include "radargauss/residuals/robust_loss.hpp"
#include "radargauss/solvers/correspondences.hpp"

namespace radargauss {

namespace {

// r = weight * Log((T_i0^-1 T_j0)^-1 T_i^-1 T_j), blocks R_i, t_i, R_j, t_j.
class RelativePoseLogResidual {
 public:
  RelativePoseLogResidual(const SE3d& measured, double weight)
      : measured_inverse_(measured.Inverse()), weight_(weight) {}

  template <typename T>
  bool operator()(const T* ri, const T* ti, const T* rj, const T* tj, T* residual) const {
    const SE3<T> a(SO3<T>(Eigen::Quaternion<T>(ri[3], ri[0], ri[1], ri[2])),
                   Eigen::Matrix<T, 3, 1>(ti[0], ti[1], ti[2]));
    const SE3<T> b(SO3<T>(Eigen::Quaternion<T>(rj[3], rj[0], rj[1], rj[2])),
                   Eigen::Matrix<T, 3, 1>(tj[0], tj[1], tj[2]));
    const Eigen::Matrix<T, 6, 1> error = (measured_inverse_.cast<T>() * (a.Inverse() * b)).Log();
    for (int k = 0; k < 6; ++k) residual[k] = T(weight_) * error[k];
    return true;
  }

 private:
  const SE3d measured_inverse_;
  const double weight_;
};

}  // namespace

double RcsResidualRms(const std::vector<RadarScan>& scans, const std::vector<SE3d>& poses, const GaussianMap& map,
                      double gate) {
  const MatchingMap matching(map, ExactMapOnly());
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < scans.size(); ++k) {
    const Correspondences c = FindCorrespondences(scans[k], matching, 0, poses[k], gate, true);
    for (const RcsTerm& term : c.rcs) {
      const double r = RcsResidualValue<double>(term, poses[k].rotation().data(), poses[k].translation());
      sum += r * r;
      ++n;
    }
  }
  return n ? std::sqrt(sum / double(n)) : 0.0;
}

const OptionTable<JointRefinementOptions>& JointRefinementOptionTable() {
  using O = JointRefinementOptions;
  static const OptionTable<O> table = [] {
    OptionTable<O> t = {
        RADARGAUSS_OPTION(O, "rounds", rounds).In(1, 1000).Help("association rounds"),
        RADARGAUSS_OPTION(O, "iterations", max_iterations_per_round).In(1, 100000).Help("Ceres iterations per round"),
        RADARGAUSS_OPTION(O, "relative_pose_prior", relative_pose_prior)
            .AtLeast(0.0)
            .Sensor()
            .Help("weight of the input's relative poses between consecutive scans (0: off)"),
        RADARGAUSS_OPTION(O, "coefficient_prior", coefficient_prior)
            .AtLeast(0.0)
            .Sensor()
            .Help("weight of the map's SH coefficients (0: off)"),
        RADARGAUSS_OPTION(O, "schur", schur).Help("SPARSE_SCHUR (the SH blocks first), else SPARSE_NORMAL_CHOLESKY"),
        RADARGAUSS_OPTION(O, "refine_threads", threads).In(1, 1024).Help("Ceres: threads"),
        RADARGAUSS_OPTION(O, "min_associated_share", min_associated_share)
            .In(0.0, 1.0)
            .Help("refuse a map on which fewer of the scans' points lie at their poses (0: never)"),
    };
    // The match's iterations, coarse levels and tolerances are not the joint problem's.
    const std::vector<std::string> unread = {
        "max_iterations",        "coarse_iterations",  "coarse_voxel_per_sigma",       "coarse_points",
        "geometric_first",       "reassociate",        "reassociation_translation",    "reassociation_rotation",
        "translation_tolerance", "rotation_tolerance", "coarse_translation_tolerance", "coarse_rotation_tolerance"};
    AppendNested(
        t, ScanMatchingOptionTable(), +[](O & o) -> auto& { return o.matching; }, "matching", "", unread);
    return t;
  }();
  return table;
}

namespace {

void CheckInputs(const std::vector<RadarScan>& scans, const std::vector<SE3d>& initial_poses,
                 const JointRefinementOptions& options) {
  CheckOptions(JointRefinementOptionTable(), options);
  ValidateOptions(options.matching);
  if (scans.size() != initial_poses.size() || scans.empty()) {
    throw std::invalid_argument("joint refinement needs one initial pose per scan (and a scan)");
  }
}

// The parameter blocks of the joint problem: a rotation and a translation per
// scan, the SH coefficients of every Gaussian with a model.
struct JointBlocks {
  JointBlocks(const std::vector<SE3d>& poses, const GaussianMap& map)
      : rotations(poses.size()), translations(poses.size()) {
    for (std::size_t k = 0; k < poses.size(); ++k) {
      rotations[k] = poses[k].rotation().quaternion().coeffs();
      translations[k] = poses[k].translation();
    }
    coefficients.resize(map.gaussians.size());
    for (std::size_t g = 0; g < map.gaussians.size(); ++g) {
      const RcsModel& model = map.gaussians[g].rcs;
      if (model.valid()) {
        coefficients[g].assign(model.coefficients.begin(),
                               model.coefficients.begin() + ShCoefficientCount(model.degree));
      }
    }
  }
  SE3d Pose(std::size_t k) const { return SE3d(SO3d::FromXyzw(rotations[k].data()), translations[k]); }

  std::vector<Eigen::Vector4d> rotations;
  std::vector<Eigen::Vector3d> translations;
  std::vector<std::vector<double>> coefficients;
};

// One association round's problem: eq. 2's terms of every scan at its
// current pose, the priors, the first pose fixed.
class JointProblem {
 public:
  JointProblem(JointBlocks& blocks, const JointRefinementOptions& options)
      : blocks_(blocks),
        options_(options),
        problem_(ProblemOptions()),
        ordering_(std::make_shared<ceres::ParameterBlockOrdering>()) {
    for (std::size_t k = 0; k < blocks_.rotations.size(); ++k) {
      problem_.AddParameterBlock(blocks_.rotations[k].data(), 4, &so3_);
      problem_.AddParameterBlock(blocks_.translations[k].data(), 3);
      ordering_->AddElementToGroup(blocks_.rotations[k].data(), 1);
      ordering_->AddElementToGroup(blocks_.translations[k].data(), 1);
    }
  }

  // Scan k's geometric and RCS terms for its correspondences c.
  void AddScan(std::size_t k, const Correspondences& c) {
    const double w = options_.matching.w_rcs;
    double* rotation = blocks_.rotations[k].data();
    double* translation = blocks_.translations[k].data();
    if (w < 1.0 && !c.geometric.empty()) {
      const double weight = (1.0 - w) / double(c.geometric.size());
      for (const GeometricTerm& term : c.geometric) {
        problem_.AddResidualBlock(
            new GeometricCostFunction(term.point_radar, c.index->Mean(term.gaussian),
                                      c.index->SqrtInformationT(term.gaussian)),
            new ceres::ScaledLoss(MakeLoss(options_.matching.geometric_loss), weight, ceres::TAKE_OWNERSHIP), rotation,
            translation);
      }
    }
    if (w > 0.0 && !c.rcs.empty()) {
      const double weight = w / double(c.rcs.size());
      const bool full = options_.matching.rcs_translation == RcsTranslation::kFull;
      for (const RcsTerm& term : c.rcs) {
        const std::uint32_t g = term.gaussian;
        ceres::CostFunction* cost =
            options_.matching.jacobians == JacobianMode::kAnalytic
                ? static_cast<ceres::CostFunction*>(new RcsCoefficientCostFunction(term, c.pose.translation(), full))
                : RcsCoefficientResidual::Create(term, c.pose.translation(), full);
        std::vector<double*> parameters = {rotation, blocks_.coefficients[g].data()};
        if (full) parameters.push_back(translation);
        problem_.AddResidualBlock(
            cost, new ceres::ScaledLoss(MakeLoss(options_.matching.rcs_loss), weight, ceres::TAKE_OWNERSHIP),
            parameters);
        if (!used_coefficients_[g]) {
          used_coefficients_[g] = true;
          ordering_->AddElementToGroup(blocks_.coefficients[g].data(), 0);  // eliminated first
        }
      }
    }
  }

  // The optional priors: consecutive relative poses, coefficients near the map's.
  void AddPriors(const std::vector<SE3d>& initial_poses, const GaussianMap& map) {
    if (options_.relative_pose_prior > 0.0) {
      for (std::size_t k = 0; k + 1 < initial_poses.size(); ++k) {
        problem_.AddResidualBlock(
            new ceres::AutoDiffCostFunction<RelativePoseLogResidual, 6, 4, 3, 4, 3>(new RelativePoseLogResidual(
                initial_poses[k].Inverse() * initial_poses[k + 1], options_.relative_pose_prior)),
            nullptr, blocks_.rotations[k].data(), blocks_.translations[k].data(), blocks_.rotations[k + 1].data(),
            blocks_.translations[k + 1].data());
      }
    }
    if (options_.coefficient_prior > 0.0) {
      for (const auto& [g, used] : used_coefficients_) {
        const int count = int(blocks_.coefficients[g].size());
        const Eigen::VectorXd initial =
            Eigen::Map<const Eigen::VectorXd>(map.gaussians[g].rcs.coefficients.data(), count);
        problem_.AddResidualBlock(
            new ceres::NormalPrior(options_.coefficient_prior * Eigen::MatrixXd::Identity(count, count), initial),
            nullptr, blocks_.coefficients[g].data());
      }
    }
  }

  ceres::Solver::Summary Solve(ceres::Solver::Options solver_options) {
    // Gauge: the first pose is fixed.
    problem_.SetParameterBlockConstant(blocks_.rotations[0].data());
    problem_.SetParameterBlockConstant(blocks_.translations[0].data());
    if (options_.schur) solver_options.linear_solver_ordering = ordering_;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem_, &summary);
    return summary;
  }

 private:
  static ceres::Problem::Options ProblemOptions() {
    ceres::Problem::Options options;
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    return options;
  }

  JointBlocks& blocks_;
  const JointRefinementOptions& options_;
  SO3Manifold so3_;
  ceres::Problem problem_;
  std::shared_ptr<ceres::ParameterBlockOrdering> ordering_;
  std::map<std::uint32_t, bool> used_coefficients_;
};

// The scans must lie on the map at their initial poses (a map of another
// sequence associates almost nothing and would "refine" into noise).
void CheckCoverage(std::size_t associated, std::size_t points, double min_share) {
  const double share = points ? double(associated) / double(points) : 0.0;
  if (share < min_share) {
    char text[240];
    std::snprintf(text, sizeof(text),
                  "%.1f %% of the scans' points lie near the map at their poses "
                  "(within --gate; --min-associated-share %.0f %%): another place's map, or another frame?",
                  100.0 * share, 100.0 * min_share);
    throw DataError(text);
  }
}

}  // namespace

JointRefinementResult RefineJointly(const std::vector<RadarScan>& scans, const std::vector<SE3d>& initial_poses,
                                    const GaussianMap& map, const JointRefinementOptions& options) {
  CheckInputs(scans, initial_poses, options);
  const auto start = std::chrono::steady_clock::now();
  JointRefinementResult result;
  result.map = map;
  JointBlocks blocks(initial_poses, map);
  const MatchingMap matching(result.map, ExactMapOnly());
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = options.schur ? ceres::SPARSE_SCHUR : ceres::SPARSE_NORMAL_CHOLESKY;
  solver_options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  solver_options.max_num_iterations = options.max_iterations_per_round;
  solver_options.num_threads = options.threads;
  solver_options.logging_type = ceres::SILENT;
  for (int round = 0; round < options.rounds; ++round) {
    JointProblem problem(blocks, options);
    std::size_t points = 0, associated = 0;
    for (std::size_t k = 0; k < scans.size(); ++k) {
      const Correspondences c = FindCorrespondences(scans[k], matching, 0, blocks.Pose(k), options.matching.gate,
                                                    options.matching.w_rcs > 0.0, options.matching.rcs_terms);
      points += scans[k].points.size();
      associated += c.geometric.size();
      problem.AddScan(k, c);
    }
    if (round == 0) CheckCoverage(associated, points, options.min_associated_share);
    problem.AddPriors(initial_poses, map);
    const ceres::Solver::Summary summary = problem.Solve(solver_options);
    if (round == 0) result.initial_cost = summary.initial_cost;
    result.final_cost = summary.final_cost;
    result.iterations += int(summary.iterations.size());
    if (!summary.IsSolutionUsable()) {
      result.reason = "Ceres: " + summary.message;
      break;
    }
    result.converged = summary.termination_type == ceres::CONVERGENCE;
    if (!result.converged) result.reason = "Ceres: " + summary.message;
  }
  for (std::size_t k = 0; k < scans.size(); ++k) result.poses.push_back(blocks.Pose(k));
  for (std::size_t g = 0; g < map.gaussians.size(); ++g) {
    for (std::size_t j = 0; j < blocks.coefficients[g].size(); ++j) {
      result.map.gaussians[g].rcs.coefficients[j] = blocks.coefficients[g][j];
    }
  }
  result.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace radargauss
