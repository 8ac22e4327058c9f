// SPDX-License-Identifier: BSD-3-Clause
// Checks of Ceres cost functions: evaluation with every block's Jacobian,
// central differences per block, relative differences.
#pragma once

#include <ceres/cost_function.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include <Eigen/Core>

#include "test_util.hpp"

namespace radargauss {

// Evaluates a cost function; returns the residuals and fills the Jacobians
// (row-major per block).
inline Eigen::VectorXd EvaluateWithJacobians(const ceres::CostFunction& cost, const std::vector<double*>& blocks,
                                             std::vector<Eigen::MatrixXd>& jacobians) {
  const int m = cost.num_residuals();
  Eigen::VectorXd residuals(m);
  std::vector<std::vector<double>> storage;
  std::vector<double*> pointers;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    storage.emplace_back(m * cost.parameter_block_sizes()[b]);
    pointers.push_back(storage.back().data());
  }
  EXPECT_TRUE(cost.Evaluate(blocks.data(), residuals.data(), pointers.data()));
  jacobians.clear();
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const int n = cost.parameter_block_sizes()[b];
    jacobians.push_back(
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(storage[b].data(), m, n));
  }
  return residuals;
}

inline Eigen::MatrixXd NumericBlockJacobian(const ceres::CostFunction& cost, std::vector<double*> blocks, int which) {
  const int n = cost.parameter_block_sizes()[which];
  Eigen::VectorXd x = Eigen::Map<Eigen::VectorXd>(blocks[which], n);
  return testing::NumericJacobian(
      [&](const Eigen::VectorXd& value) {
        Eigen::VectorXd copy = value;
        std::vector<double*> b = blocks;
        b[which] = copy.data();
        Eigen::VectorXd r(cost.num_residuals());
        cost.Evaluate(b.data(), r.data(), nullptr);
        return r;
      },
      x, 1e-6);
}

inline double Relative(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(1e-12, b.norm());
}

}  // namespace radargauss
