#include "radargauss/solvers/joint_refinement.hpp"

#include <ceres/normal_prior.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <chrono>
#include <map>
#include <stdexcept>

#include "radargauss/lie/manifold.hpp"
#include "radargauss/residuals/geometric_residual.hpp"
#include "radargauss/residuals/rcs_residual.hpp"

namespace radargauss {

namespace {

// r = weight * Log((T_i0^-1 T_j0)^-1 T_i^-1 T_j), blocks R_i, t_i, R_j, t_j.
class RelativePoseResidual {
 public:
  RelativePoseResidual(const SE3d& measured, double weight) : measured_inverse_(measured.Inverse()), weight_(weight) {}

  template <typename T>
  bool operator()(const T* ri, const T* ti, const T* rj, const T* tj, T* residual) const {
    const SE3<T> a(SO3<T>(Eigen::Quaternion<T>(ri[3], ri[0], ri[1], ri[2])), Eigen::Matrix<T, 3, 1>(ti[0], ti[1], ti[2]));
    const SE3<T> b(SO3<T>(Eigen::Quaternion<T>(rj[3], rj[0], rj[1], rj[2])), Eigen::Matrix<T, 3, 1>(tj[0], tj[1], tj[2]));
    const Eigen::Matrix<T, 6, 1> error = (measured_inverse_.cast<T>() * (a.Inverse() * b)).Log();
    for (int k = 0; k < 6; ++k) residual[k] = T(weight_) * error[k];
    return true;
  }

 private:
  const SE3d measured_inverse_;
  const double weight_;
};

}  // namespace

double RcsResidualRms(const std::vector<RadarScan>& scans, const std::vector<SE3d>& poses,
                      const GaussianMap& map, double gate) {
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

JointRefinementResult RefineJointly(const std::vector<RadarScan>& scans,
                                    const std::vector<SE3d>& initial_poses, const GaussianMap& map,
                                    const JointRefinementOptions& options) {
  ValidateOptions(options.matching);
  if (scans.size() != initial_poses.size() || scans.empty()) {
    throw std::invalid_argument("joint refinement needs one initial pose per scan (and a scan)");
  }
  if (options.rounds < 1 || options.max_iterations_per_round < 1 || options.relative_pose_prior < 0.0 ||
      options.coefficient_prior < 0.0) {
    throw std::invalid_argument("joint refinement: rounds and iterations must be >= 1, priors >= 0");
  }
  const auto start = std::chrono::steady_clock::now();
  JointRefinementResult result;
  result.map = map;
  const double w = options.matching.w_rcs;
  const bool full = options.matching.rcs_translation == RcsTranslation::kFull;
  const std::size_t n = scans.size();
  std::vector<Eigen::Vector4d> rotations(n);
  std::vector<Eigen::Vector3d> translations(n);
  for (std::size_t k = 0; k < n; ++k) {
    rotations[k] = initial_poses[k].rotation().quaternion().coeffs();
    translations[k] = initial_poses[k].translation();
  }
  std::vector<std::vector<double>> coefficients(map.gaussians.size());
  for (std::size_t g = 0; g < map.gaussians.size(); ++g) {
    const RcsModel& model = map.gaussians[g].rcs;
    if (model.valid()) {
      coefficients[g].assign(model.coefficients.begin(), model.coefficients.begin() + ShCoefficientCount(model.degree));
    }
  }
  const MatchingMap matching(result.map, ExactMapOnly());
  SO3Manifold so3;
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = options.schur ? ceres::SPARSE_SCHUR : ceres::SPARSE_NORMAL_CHOLESKY;
  solver_options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  solver_options.max_num_iterations = options.max_iterations_per_round;
  solver_options.num_threads = options.threads;
  solver_options.logging_type = ceres::SILENT;

  for (int round = 0; round < options.rounds; ++round) {
    ceres::Problem::Options problem_options;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    for (std::size_t k = 0; k < n; ++k) {
      problem.AddParameterBlock(rotations[k].data(), 4, &so3);
      problem.AddParameterBlock(translations[k].data(), 3);
      ordering->AddElementToGroup(rotations[k].data(), 1);
      ordering->AddElementToGroup(translations[k].data(), 1);
    }
    std::map<std::uint32_t, bool> used_coefficients;
    for (std::size_t k = 0; k < n; ++k) {
      const SE3d pose(SO3d::FromXyzw(rotations[k].data()), translations[k]);
      const Correspondences c = FindCorrespondences(scans[k], matching, 0, pose, options.matching.gate, w > 0.0);
      if (w < 1.0 && !c.geometric.empty()) {
        const double weight = (1.0 - w) / double(c.geometric.size());
        for (const GeometricTerm& term : c.geometric) {
          problem.AddResidualBlock(
              new GeometricCostFunction(term.point_radar, c.index->Mean(term.gaussian),
                                        c.index->SqrtInformationT(term.gaussian)),
              new ceres::ScaledLoss(MakeLoss(options.matching.geometric_loss), weight, ceres::TAKE_OWNERSHIP),
              rotations[k].data(), translations[k].data());
        }
      }
      if (w > 0.0 && !c.rcs.empty()) {
        const double weight = w / double(c.rcs.size());
        for (const RcsTerm& term : c.rcs) {
          const std::uint32_t g = term.gaussian;
          ceres::CostFunction* cost =
              options.matching.jacobians == JacobianMode::kAnalytic
                  ? static_cast<ceres::CostFunction*>(new RcsCoefficientCostFunction(term, c.pose.translation(), full))
                  : RcsCoefficientResidual::Create(term, c.pose.translation(), full);
          std::vector<double*> blocks = {rotations[k].data(), coefficients[g].data()};
          if (full) blocks.push_back(translations[k].data());
          problem.AddResidualBlock(
              cost, new ceres::ScaledLoss(MakeLoss(options.matching.rcs_loss), weight, ceres::TAKE_OWNERSHIP),
              blocks);
          if (!used_coefficients[g]) {
            used_coefficients[g] = true;
            ordering->AddElementToGroup(coefficients[g].data(), 0);  // eliminated first
          }
        }
      }
    }
    if (options.relative_pose_prior > 0.0) {
      for (std::size_t k = 0; k + 1 < n; ++k) {
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<RelativePoseResidual, 6, 4, 3, 4, 3>(new RelativePoseResidual(
                initial_poses[k].Inverse() * initial_poses[k + 1], options.relative_pose_prior)),
            nullptr, rotations[k].data(), translations[k].data(), rotations[k + 1].data(),
            translations[k + 1].data());
      }
    }
    if (options.coefficient_prior > 0.0) {
      for (const auto& [g, used] : used_coefficients) {
        const int count = int(coefficients[g].size());
        const Eigen::VectorXd initial = Eigen::Map<const Eigen::VectorXd>(map.gaussians[g].rcs.coefficients.data(), count);
        problem.AddResidualBlock(
            new ceres::NormalPrior(options.coefficient_prior * Eigen::MatrixXd::Identity(count, count), initial),
            nullptr, coefficients[g].data());
      }
    }
    // Gauge: the first pose is fixed.
    problem.SetParameterBlockConstant(rotations[0].data());
    problem.SetParameterBlockConstant(translations[0].data());
    if (options.schur) solver_options.linear_solver_ordering = ordering;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
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
  result.poses.resize(n);
  for (std::size_t k = 0; k < n; ++k) result.poses[k] = SE3d(SO3d::FromXyzw(rotations[k].data()), translations[k]);
  for (std::size_t g = 0; g < map.gaussians.size(); ++g) {
    for (std::size_t j = 0; j < coefficients[g].size(); ++j) result.map.gaussians[g].rcs.coefficients[j] = coefficients[g][j];
  }
  result.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace radargauss
