// SPDX-License-Identifier: BSD-3-Clause
// Calibration only where the motion shows it (docs/design/solvers.md, "The
// calibration gate"): the information the window's data hold about a
// calibration block, its directions that they observe, and a term that
// holds the others where they are for one solve.
#pragma once

#include <memory>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/problem.h>
#include <Eigen/Core>

#include "radargauss/lie/so3.hpp"

namespace radargauss {

// A calibration block's place in the window's Gauss-Newton matrix (its
// tangent columns), the information its first-state prior holds, and the
// std below which the data count as observing a direction.
struct CalibrationBlock {
  int offset = 0;
  int size = 0;
  Eigen::MatrixXd prior_information;  // size x size
  double observed_std = 0.0;
};

// What the window knows of the block: its marginal covariance (the Schur
// complement of the whole matrix onto the block, inverted: what the
// window's uncertainty would state), and the directions whose information
// from the data alone (the prior's taken out) leaves a std above
// observed_std: orthonormal columns, none when every direction is observed.
struct BlockObservation {
  Eigen::MatrixXd covariance;
  Eigen::MatrixXd unobserved;
  Eigen::VectorXd std() const { return covariance.diagonal().cwiseMax(0.0).cwiseSqrt(); }
  bool observed() const { return unobserved.cols() == 0; }
};
BlockObservation ObserveBlock(const Eigen::MatrixXd& information, const CalibrationBlock& block);

// One estimated calibration block of a window: its parameters, the std of
// its first-state prior (0: none) and the std below which a direction
// counts as observed.
struct GatedBlock {
  double* data = nullptr;
  int size = 0;
  bool rotation = false;  // x y z w with a right perturbation; else Euclidean
  double prior_std = 0.0;
  double observed_std = 0.0;
};
// Each gated block's observation in `problem`, whose variable blocks are
// `blocks` in the order of its Gauss-Newton matrix; with `hold`, a term
// added to `problem` (owned by `holds`, for one solve) holds each block along
// its unobserved directions at 1/1000 of its observed_std.
std::vector<BlockObservation> GateCalibration(ceres::Problem& problem, const std::vector<double*>& blocks,
                                              const std::vector<GatedBlock>& gated, bool hold,
                                              std::vector<std::unique_ptr<ceres::CostFunction>>& holds);

// r = w P (x - anchor) with P = V V^T: holds a Euclidean block at `anchor`
// along the columns of V (orthonormal), free across them.
std::unique_ptr<ceres::CostFunction> HoldAlong(const Eigen::VectorXd& anchor, const Eigen::MatrixXd& directions,
                                               double weight);
// The same on a rotation block (x y z w, right perturbation): r = w P Log(R_anchor^T R).
std::unique_ptr<ceres::CostFunction> HoldRotationAlong(const SO3d& anchor, const Eigen::MatrixXd& directions,
                                                       double weight);

}  // namespace radargauss
