// SPDX-License-Identifier: BSD-3-Clause
// Marginalisation by the Schur complement (docs/design/solvers.md, "The sliding
// window"): the factors on the blocks that leave a problem, linearised at
// their current values, become one Gaussian prior on the blocks they share
// with the rest,
//
//   H = J^T J, b = J^T r over [leaving; kept],
//   H* = H_kk - H_kl H_ll^+ H_lk,  b* = b_k - H_kl H_ll^+ b_l,
//   prior: r(x) = J* (x [-] x0) + r*,  J*^T J* = H*,  J*^T r* = b*,
//
// with [-] each kept block's manifold Minus (its tangent at x0). On a
// linear-Gaussian problem the prior leaves the kept blocks' optimum exactly
// where the whole problem has it.
#pragma once

#include <memory>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/crs_matrix.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>

#include <Eigen/Core>

namespace radargauss {

class MarginalizationPrior final : public ceres::CostFunction {
 public:
  // One kept block: its address in the problems the prior joins, its value at
  // the linearisation and its manifold (null: Euclidean).
  struct Block {
    double* address = nullptr;
    Eigen::VectorXd linearisation;
    const ceres::Manifold* manifold = nullptr;
    int tangent_size = 0;
  };

  MarginalizationPrior(std::vector<Block> blocks, Eigen::MatrixXd jacobian, Eigen::VectorXd residual);

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  // The kept blocks' addresses, in the order Evaluate takes them.
  std::vector<double*> parameter_blocks() const;
  const std::vector<Block>& blocks() const { return blocks_; }

 private:
  std::vector<Block> blocks_;
  Eigen::MatrixXd jacobian_;  // J*, tangent columns
  Eigen::VectorXd residual_;  // r*
};

// The Jacobian Ceres's Problem::Evaluate gives (tangent columns), dense.
Eigen::MatrixXd DenseJacobian(const ceres::CRSMatrix& crs);
// J^T J of `problem` over the tangent of `blocks` (its variable blocks, in
// this order); offset[b] is block b's first column, offset.back() the size.
Eigen::MatrixXd GaussNewtonMatrix(ceres::Problem& problem, const std::vector<double*>& blocks,
                                  std::vector<int>& offset);

// The prior left by removing `leaving` and the residual blocks `factors` (all
// those of `problem` that touch `leaving`, and maybe more) from `problem`,
// on `kept` (the other blocks those factors touch; the constant ones may be
// left out). Directions with eigenvalues of H* below `relative_floor` times
// its largest carry no information and are left out. Null when nothing is left.
// The manifolds of `kept` must outlive the prior.
std::shared_ptr<MarginalizationPrior> Marginalize(ceres::Problem& problem,
                                                  const std::vector<ceres::ResidualBlockId>& factors,
                                                  const std::vector<double*>& leaving, const std::vector<double*>& kept,
                                                  double relative_floor = 1e-12);

}  // namespace radargauss
