// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/calibration_gate.hpp"

#include <algorithm>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "radargauss/residuals/priors.hpp"
#include "radargauss/residuals/rotation_residual.hpp"
#include "radargauss/solvers/marginalization.hpp"

namespace radargauss {

namespace {

class LinearHold final : public ceres::CostFunction {
 public:
  LinearHold(const Eigen::VectorXd& anchor, const Eigen::MatrixXd& W) : anchor_(anchor), W_(W) {
    set_num_residuals(int(W.rows()));
    mutable_parameter_block_sizes()->push_back(int(anchor.size()));
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Eigen::Map<const Eigen::VectorXd> x(parameters[0], anchor_.size());
    Eigen::Map<Eigen::VectorXd>(residuals, W_.rows()) = W_ * (x - anchor_);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(jacobians[0], W_.rows(),
                                                                                         W_.cols()) = W_;
    }
    return true;
  }

 private:
  Eigen::VectorXd anchor_;
  Eigen::MatrixXd W_;
};

}  // namespace

BlockObservation ObserveBlock(const Eigen::MatrixXd& H, const CalibrationBlock& block) {
  const int n = int(H.rows()), c = block.size, o = block.offset;
  // The rest's columns, then the Schur complement S = H_cc - H_cr H_rr^+ H_rc.
  Eigen::MatrixXd H_rr(n - c, n - c), H_rc(n - c, c);
  const auto rest = [&](int i) { return i < o ? i : i + c; };
  for (int i = 0; i < n - c; ++i) {
    for (int j = 0; j < n - c; ++j) H_rr(i, j) = H(rest(i), rest(j));
    for (int j = 0; j < c; ++j) H_rc(i, j) = H(rest(i), o + j);
  }
  const Eigen::MatrixXd S = H.block(o, o, c, c) - H_rc.transpose() * H_rr.completeOrthogonalDecomposition().solve(H_rc);
  BlockObservation observation;
  observation.covariance = S.completeOrthogonalDecomposition().pseudoInverse();
  // The data's share: the prior taken out; a direction is observed when it
  // alone states a std of at most observed_std (information 1 / std^2).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> data(0.5 * (S + S.transpose()) - block.prior_information);
  const double needed = 1.0 / (block.observed_std * block.observed_std);
  std::vector<int> unobserved;
  for (int k = 0; k < c; ++k) {
    if (data.eigenvalues()(k) < needed) unobserved.push_back(k);
  }
  observation.unobserved.resize(c, Eigen::Index(unobserved.size()));
  for (std::size_t k = 0; k < unobserved.size(); ++k) {
    observation.unobserved.col(Eigen::Index(k)) = data.eigenvectors().col(unobserved[k]);
  }
  return observation;
}

std::unique_ptr<ceres::CostFunction> HoldAlong(const Eigen::VectorXd& anchor, const Eigen::MatrixXd& directions,
                                               double weight) {
  return std::make_unique<LinearHold>(anchor, weight * directions * directions.transpose());
}

std::unique_ptr<ceres::CostFunction> HoldRotationAlong(const SO3d& anchor, const Eigen::MatrixXd& directions,
                                                       double weight) {
  RotationPrior prior;
  prior.predicted = anchor;
  prior.sqrt_information = weight * directions * directions.transpose();
  return std::make_unique<RotationCostFunction>(prior);
}

std::vector<BlockObservation> GateCalibration(ceres::Problem& problem, const std::vector<double*>& blocks,
                                              const std::vector<GatedBlock>& gated, bool hold,
                                              std::vector<std::unique_ptr<ceres::CostFunction>>& holds) {
  std::vector<int> offset;
  const Eigen::MatrixXd H = GaussNewtonMatrix(problem, blocks, offset);
  std::vector<BlockObservation> observations;
  for (const GatedBlock& g : gated) {
    const std::size_t b = std::find(blocks.begin(), blocks.end(), g.data) - blocks.begin();
    if (b == blocks.size()) throw std::invalid_argument("GateCalibration: a gated block is not a variable block");
    CalibrationBlock block;
    block.offset = offset[b];
    block.size = g.size;
    block.prior_information =
        Eigen::MatrixXd::Identity(g.size, g.size) * (g.prior_std > 0.0 ? 1.0 / (g.prior_std * g.prior_std) : 0.0);
    block.observed_std = g.observed_std;
    observations.push_back(ObserveBlock(H, block));
  }
  if (!hold) return observations;
  constexpr double kHold = 1e3;  // the held directions' weight: 1/1000 of their observed std
  for (std::size_t k = 0; k < gated.size(); ++k) {
    const GatedBlock& g = gated[k];
    const Eigen::MatrixXd& unobserved = observations[k].unobserved;
    if (unobserved.cols() == 0) continue;
    holds.push_back(
        g.rotation ? HoldRotationAlong(SO3d::FromXyzw(g.data), unobserved, kHold / g.observed_std)
                   : HoldAlong(Eigen::Map<const Eigen::VectorXd>(g.data, g.size), unobserved, kHold / g.observed_std));
    problem.AddResidualBlock(holds.back().get(), nullptr, g.data);
  }
  return observations;
}

}  // namespace radargauss
