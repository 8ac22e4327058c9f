// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/window_solvers.hpp"

#include <algorithm>
#include <cmath>

#include <ceres/crs_matrix.h>
#include <ceres/manifold.h>
#include <ceres/solver.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace radargauss {

// The own Gauss-Newton on the window: the normal equations of the terms'
// tangent Jacobians (Ceres evaluates them), block-banded and solved by a
// sparse LDL^T, each step halved while it raises the cost.
WindowSolveSummary SolveWithGaussNewton(ceres::Problem& problem, const std::vector<double*>& blocks,
                                        int max_iterations) {
  WindowSolveSummary summary;
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = blocks;
  double cost = 0.0;
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  problem.Evaluate(evaluate, &cost, &residuals, nullptr, &crs);
  summary.initial_cost = cost;
  std::vector<Eigen::VectorXd> saved(blocks.size());
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>> J(
        crs.num_rows, crs.num_cols, Eigen::Index(crs.values.size()), crs.rows.data(), crs.cols.data(),
        crs.values.data());
    const Eigen::VectorXd r = Eigen::Map<const Eigen::VectorXd>(residuals.data(), Eigen::Index(residuals.size()));
    Eigen::SparseMatrix<double> H = Eigen::SparseMatrix<double>(J.transpose()) * J;
    for (int k = 0; k < H.rows(); ++k) H.coeffRef(k, k) += 1e-12 * (1.0 + std::abs(H.coeff(k, k)));
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factor(H);
    const Eigen::VectorXd step = factor.solve(-(J.transpose() * r));
    ++summary.iterations;
    for (std::size_t b = 0; b < blocks.size(); ++b) {
      saved[b] = Eigen::Map<const Eigen::VectorXd>(blocks[b], problem.ParameterBlockSize(blocks[b]));
    }
    double scale = 1.0, new_cost = cost;
    for (int halving = 0; halving < 8; ++halving, scale *= 0.5) {
      int column = 0;
      for (std::size_t b = 0; b < blocks.size(); ++b) {
        const ceres::Manifold* manifold = problem.GetManifold(blocks[b]);
        const int n = manifold == nullptr ? int(saved[b].size()) : manifold->TangentSize();
        const Eigen::VectorXd delta = scale * step.segment(column, n);
        if (manifold == nullptr) {
          Eigen::Map<Eigen::VectorXd>(blocks[b], n) = saved[b] + delta;
        } else {
          manifold->Plus(saved[b].data(), delta.data(), blocks[b]);
        }
        column += n;
      }
      problem.Evaluate(evaluate, &new_cost, nullptr, nullptr, nullptr);
      if (new_cost <= cost) break;
    }
    if (new_cost > cost) {  // no halving helped: stay where the cost was lowest
      for (std::size_t b = 0; b < blocks.size(); ++b) {
        std::copy(saved[b].data(), saved[b].data() + saved[b].size(), blocks[b]);
      }
      summary.converged = true;
      break;
    }
    const bool small = cost - new_cost <= 1e-10 * cost || (scale * step).norm() < 1e-10;
    problem.Evaluate(evaluate, &cost, &residuals, nullptr, &crs);
    if (small) {
      summary.converged = true;
      break;
    }
  }
  summary.final_cost = cost;
  return summary;
}

WindowSolveSummary SolveWithCeres(ceres::Problem& problem, const InertialWindowOptions& options) {
  ceres::Solver::Options solver;
  // The window's Hessian is block-banded: SuiteSparse's Cholesky (dense
  // normal equations cost 5x at ten states; Ceres's EIGEN_SPARSE would
  // instantiate Eigen's templates in both Debian's library and ours, whose
  // allocators disagree under the address sanitizer).
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  // The IMU's prediction starts the new state near the optimum: LM starts
  // nearly Gauss-Newton (Ceres's 1e4 damps the first steps into many small ones).
  solver.initial_trust_region_radius = 1e8;
  solver.trust_region_strategy_type =
      options.solver == WindowSolver::kCeresDogleg ? ceres::DOGLEG : ceres::LEVENBERG_MARQUARDT;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = 1;
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(solver, &problem, &ceres_summary);
  WindowSolveSummary summary;
  summary.iterations = int(ceres_summary.iterations.size()) - 1;
  summary.initial_cost = ceres_summary.initial_cost;
  summary.final_cost = ceres_summary.final_cost;
  summary.converged = ceres_summary.termination_type == ceres::CONVERGENCE;
  return summary;
}

}  // namespace radargauss
