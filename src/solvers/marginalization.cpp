// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/marginalization.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <ceres/crs_matrix.h>

#include <Eigen/Eigenvalues>

namespace radargauss {

MarginalizationPrior::MarginalizationPrior(std::vector<Block> blocks, Eigen::MatrixXd jacobian,
                                           Eigen::VectorXd residual)
    : blocks_(std::move(blocks)), jacobian_(std::move(jacobian)), residual_(std::move(residual)) {
  int tangent = 0;
  for (const Block& block : blocks_) {
    mutable_parameter_block_sizes()->push_back(int(block.linearisation.size()));
    tangent += block.tangent_size;
  }
  if (tangent != jacobian_.cols() || jacobian_.rows() != residual_.size()) {
    throw std::invalid_argument("MarginalizationPrior: the Jacobian does not match the blocks");
  }
  set_num_residuals(int(residual_.size()));
}

std::vector<double*> MarginalizationPrior::parameter_blocks() const {
  std::vector<double*> addresses;
  for (const Block& block : blocks_) addresses.push_back(block.address);
  return addresses;
}

bool MarginalizationPrior::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Eigen::VectorXd delta(jacobian_.cols());
  int column = 0;
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    const Block& block = blocks_[b];
    const int n = block.tangent_size;
    if (block.manifold == nullptr) {
      delta.segment(column, n) = Eigen::Map<const Eigen::VectorXd>(parameters[b], n) - block.linearisation;
    } else if (!block.manifold->Minus(parameters[b], block.linearisation.data(), delta.data() + column)) {
      return false;
    }
    column += n;
  }
  Eigen::Map<Eigen::VectorXd> r(residuals, num_residuals());
  r = residual_ + jacobian_ * delta;
  if (jacobians == nullptr) return true;
  column = 0;
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    const Block& block = blocks_[b];
    const int n = block.tangent_size, ambient = int(block.linearisation.size());
    if (jacobians[b] != nullptr) {
      Eigen::Map<RowMajor> J(jacobians[b], num_residuals(), ambient);
      if (block.manifold == nullptr) {
        J = jacobian_.middleCols(column, n);
      } else {
        // d(x [-] x0)/dx to first order: the manifold's Minus Jacobian at x.
        RowMajor minus(n, ambient);
        if (!block.manifold->MinusJacobian(parameters[b], minus.data())) return false;
        J = jacobian_.middleCols(column, n) * minus;
      }
    }
    column += n;
  }
  return true;
}

Eigen::MatrixXd DenseJacobian(const ceres::CRSMatrix& crs) {
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) J(row, crs.cols[k]) = crs.values[k];
  }
  return J;
}

Eigen::MatrixXd GaussNewtonMatrix(ceres::Problem& problem, const std::vector<double*>& blocks,
                                  std::vector<int>& offset) {
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = blocks;
  ceres::CRSMatrix crs;
  problem.Evaluate(evaluate, nullptr, nullptr, nullptr, &crs);
  offset.assign(blocks.size() + 1, 0);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const ceres::Manifold* manifold = problem.GetManifold(blocks[b]);
    offset[b + 1] = offset[b] + (manifold ? manifold->TangentSize() : problem.ParameterBlockSize(blocks[b]));
  }
  const Eigen::MatrixXd J = DenseJacobian(crs);
  return J.transpose() * J;
}

namespace {

int TangentSize(const ceres::Problem& problem, double* block) {
  const ceres::Manifold* manifold = problem.GetManifold(block);
  return manifold == nullptr ? problem.ParameterBlockSize(block) : manifold->TangentSize();
}

// The pseudo-inverse of a symmetric matrix: eigenvalues below floor are zero.
Eigen::MatrixXd SymmetricPseudoInverse(const Eigen::MatrixXd& A, double floor) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(0.5 * (A + A.transpose()));
  const Eigen::VectorXd values = eigen.eigenvalues();
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(values.size());
  for (int k = 0; k < values.size(); ++k) {
    if (values(k) > floor) inverse(k) = 1.0 / values(k);
  }
  return eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
}

}  // namespace

std::shared_ptr<MarginalizationPrior> Marginalize(ceres::Problem& problem,
                                                  const std::vector<ceres::ResidualBlockId>& factors,
                                                  const std::vector<double*>& leaving, const std::vector<double*>& kept,
                                                  double relative_floor) {
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.residual_blocks = factors;
  evaluate.parameter_blocks = leaving;
  evaluate.parameter_blocks.insert(evaluate.parameter_blocks.end(), kept.begin(), kept.end());
  int leaving_size = 0, kept_size = 0;
  for (double* block : leaving) leaving_size += TangentSize(problem, block);
  for (double* block : kept) kept_size += TangentSize(problem, block);

  double cost = 0.0;
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  if (!problem.Evaluate(evaluate, &cost, &residuals, nullptr, &crs)) {
    throw std::runtime_error("Marginalize: the factors could not be evaluated");
  }
  const Eigen::MatrixXd J = DenseJacobian(crs);
  const Eigen::VectorXd r = Eigen::Map<const Eigen::VectorXd>(residuals.data(), Eigen::Index(residuals.size()));
  const Eigen::MatrixXd H = J.transpose() * J;
  const Eigen::VectorXd b = J.transpose() * r;

  // The Schur complement of the leaving blocks.
  const double scale = std::max(1.0, H.diagonal().cwiseAbs().maxCoeff());
  const Eigen::MatrixXd H_ll_inverse =
      SymmetricPseudoInverse(H.topLeftCorner(leaving_size, leaving_size), relative_floor * scale);
  const Eigen::MatrixXd H_kl = H.bottomLeftCorner(kept_size, leaving_size);
  const Eigen::MatrixXd H_star = H.bottomRightCorner(kept_size, kept_size) - H_kl * H_ll_inverse * H_kl.transpose();
  const Eigen::VectorXd b_star = b.tail(kept_size) - H_kl * H_ll_inverse * b.head(leaving_size);

  // H* = V L V^T: J* = L^(1/2) V^T and r* = L^(-1/2) V^T b* over the informative directions.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(0.5 * (H_star + H_star.transpose()));
  const double floor = relative_floor * std::max(1e-300, eigen.eigenvalues().maxCoeff());
  std::vector<int> informative;
  for (int k = 0; k < eigen.eigenvalues().size(); ++k) {
    if (eigen.eigenvalues()(k) > floor) informative.push_back(k);
  }
  if (informative.empty()) return nullptr;
  Eigen::MatrixXd J_star(informative.size(), kept_size);
  Eigen::VectorXd r_star(informative.size());
  for (std::size_t i = 0; i < informative.size(); ++i) {
    const double value = eigen.eigenvalues()(informative[i]);
    const Eigen::VectorXd direction = eigen.eigenvectors().col(informative[i]);
    J_star.row(Eigen::Index(i)) = std::sqrt(value) * direction.transpose();
    r_star(Eigen::Index(i)) = direction.dot(b_star) / std::sqrt(value);
  }

  std::vector<MarginalizationPrior::Block> blocks;
  for (double* address : kept) {
    MarginalizationPrior::Block block;
    block.address = address;
    block.linearisation = Eigen::Map<const Eigen::VectorXd>(address, problem.ParameterBlockSize(address));
    block.manifold = problem.GetManifold(address);
    block.tangent_size = TangentSize(problem, address);
    blocks.push_back(std::move(block));
  }
  return std::make_shared<MarginalizationPrior>(std::move(blocks), std::move(J_star), std::move(r_star));
}

}  // namespace radargauss
