// SPDX-License-Identifier: BSD-3-Clause
// How analytic terms enter a ceres::Problem (CeresScanProblem,
// ceres_scan_problem.hpp): TermRangeCost evaluates a range of terms as one
// residual block, as their rows or in square-root form; TermBlocks keeps the
// blocks of one kind of term across associations. Internal to the solvers.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/problem.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "radargauss/residuals/robust_loss.hpp"

namespace radargauss::internal {

// The sizes of a ceres::SizedCostFunction, at compile time.
template <int Residuals, int... BlockSizes>
struct SizedDims {
  static constexpr int kResiduals = Residuals;
  static constexpr int kBlocks = sizeof...(BlockSizes);
  static constexpr int kBlockSizes[kBlocks] = {BlockSizes...};
};
template <int Residuals, int... BlockSizes>
SizedDims<Residuals, BlockSizes...> DimsOf(const ceres::SizedCostFunction<Residuals, BlockSizes...>*);

// Terms of one kind (analytic cost functions `Term`) as one shared residual
// block (CeresScanProblem), each term with its robust loss applied in its own
// residual (ApplyLoss). Shared rows: term k's residuals and Jacobian rows sit
// at k times one term's (Ceres's Jacobians are row-major). Square root: the
// block's square-root form (EvaluateSquareRoot).
template <typename Term>
class TermRangeCost final : public ceres::CostFunction {
  using Dims = decltype(DimsOf(static_cast<const Term*>(nullptr)));
  static constexpr int kRows = Dims::kResiduals;
  static constexpr int kMaxBlockSize = 4;  // the quaternion
  // The pose blocks a term takes: the rotation (x y z w), then the translation or not.
  static constexpr bool kWithTranslation = Dims::kBlocks == 2;
  static_assert(Dims::kBlockSizes[0] == 4 && (Dims::kBlocks == 1 || (kWithTranslation && Dims::kBlockSizes[1] == 3)),
                "a rotation block (x y z w), then at most a translation block");
  static constexpr int kAmbient = kWithTranslation ? 7 : 4;
  static constexpr int kTangent = kWithTranslation ? 6 : 3;

 public:
  // `loss`: each term's robust loss (nullptr: trivial); it must outlive this.
  TermRangeCost(const ceres::LossFunction* loss, bool square_root) : loss_(loss), square_root_(square_root) {
    *mutable_parameter_block_sizes() = std::vector<std::int32_t>(Dims::kBlockSizes, Dims::kBlockSizes + Dims::kBlocks);
  }

  void Reset(std::vector<const Term*> terms) {
    terms_ = std::move(terms);
    set_num_residuals(square_root_ ? kTangent + 1 : kRows * int(terms_.size()));
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    if (square_root_) return EvaluateSquareRoot(parameters, residuals, jacobians);
    double* term_jacobians[Dims::kBlocks];
    for (std::size_t k = 0; k < terms_.size(); ++k) {
      double* r = residuals + k * kRows;
      if (jacobians != nullptr) {
        for (int b = 0; b < Dims::kBlocks; ++b) {
          term_jacobians[b] = jacobians[b] != nullptr ? jacobians[b] + k * kRows * Dims::kBlockSizes[b] : nullptr;
        }
      }
      if (!terms_[k]->Term::Evaluate(parameters, r, jacobians != nullptr ? term_jacobians : nullptr)) return false;
      if (loss_ != nullptr) ApplyLoss(r, jacobians != nullptr ? term_jacobians : nullptr);
    }
    return true;
  }

 private:
  // r -> f r with f = sqrt(rho(s) / s), s = |r|^2, so that |f r|^2 = rho(s),
  // and J -> its exact Jacobian f (J + (rho'/rho - 1/s) r r^T J);
  // f = sqrt(rho'(0)) at s = 0.
  void ApplyLoss(double* r, double* const* J) const {
    double s = 0.0;
    for (int i = 0; i < kRows; ++i) s += r[i] * r[i];
    double rho[3];
    loss_->Evaluate(s, rho);
    const bool at_zero = !(s > 0.0) || !(rho[0] > 0.0);
    const double f = at_zero ? std::sqrt(rho[1]) : std::sqrt(rho[0] / s);
    const double c = at_zero ? 0.0 : rho[1] / rho[0] - 1.0 / s;
    for (int b = 0; J != nullptr && b < Dims::kBlocks; ++b) {
      if (J[b] == nullptr) continue;
      const int n = Dims::kBlockSizes[b];
      double rt_J[kMaxBlockSize] = {};  // r^T J
      for (int i = 0; i < kRows; ++i)
        for (int j = 0; j < n; ++j) rt_J[j] += r[i] * J[b][i * n + j];
      for (int i = 0; i < kRows; ++i)
        for (int j = 0; j < n; ++j) J[b][i * n + j] = f * (J[b][i * n + j] + c * r[i] * rt_J[j]);
    }
    for (int i = 0; i < kRows; ++i) r[i] *= f;
  }

  // The terms' square-root form (CeresScanProblem): with r and J the terms'
  // stacked residuals (loss applied) and Jacobian on the tangent space,
  // R^T R = J^T J and R^T z = J^T r; residuals [z; sqrt(|r|^2 - |z|^2)] and
  // Jacobian [R; 0] (with residuals only: [|r|; 0]). J^T J and J^T r are
  // summed on the ambient coordinates and projected once by the rotation's
  // Plus Jacobian.
  bool EvaluateSquareRoot(double const* const* parameters, double* residuals, double** jacobians) const {
    double ss = 0.0;
    Eigen::Matrix<double, kAmbient, kAmbient> A = Eigen::Matrix<double, kAmbient, kAmbient>::Zero();
    Eigen::Matrix<double, kAmbient, 1> b = Eigen::Matrix<double, kAmbient, 1>::Zero();
    double r[kRows];
    // The term's Jacobian blocks (row-major): rotation J_q, then translation J_t.
    Eigen::Matrix<double, kRows, 4, Eigen::RowMajor> J_q;
    Eigen::Matrix<double, kRows, 3, Eigen::RowMajor> J_t;
    double* term_jacobians[2] = {J_q.data(), J_t.data()};
    const bool with_jacobians = jacobians != nullptr;
    for (std::size_t k = 0; k < terms_.size(); ++k) {
      if (!terms_[k]->Term::Evaluate(parameters, r, with_jacobians ? term_jacobians : nullptr)) return false;
      if (loss_ != nullptr) ApplyLoss(r, with_jacobians ? term_jacobians : nullptr);
      const Eigen::Map<const Eigen::Matrix<double, kRows, 1>> residual(r);
      ss += residual.squaredNorm();
      if (!with_jacobians) continue;
      // The upper triangle of J^T J (mirrored below), and J^T r.
      A.template topLeftCorner<4, 4>().noalias() += J_q.transpose() * J_q;
      b.template head<4>().noalias() += J_q.transpose() * residual;
      if constexpr (kWithTranslation) {
        A.template topRightCorner<4, 3>().noalias() += J_q.transpose() * J_t;
        A.template bottomRightCorner<3, 3>().noalias() += J_t.transpose() * J_t;
        b.template tail<3>().noalias() += J_t.transpose() * residual;
      }
    }
    A.template triangularView<Eigen::StrictlyLower>() = A.transpose();
    Eigen::Map<Eigen::Matrix<double, kTangent + 1, 1>> out(residuals);
    if (!with_jacobians) {
      out.setZero();
      out[0] = std::sqrt(ss);
      return true;
    }
    // Tangent coordinates: the rotation's Plus Jacobian P (4 x 3), identity for translations.
    Eigen::Matrix<double, 4, 3, Eigen::RowMajor> P;
    SO3Manifold().PlusJacobian(parameters[0], P.data());
    Eigen::Matrix<double, kAmbient, kTangent> T = Eigen::Matrix<double, kAmbient, kTangent>::Zero();
    T.template topLeftCorner<4, 3>() = P;
    T.template bottomRightCorner<kAmbient - 4, kTangent - 3>().setIdentity();
    const Eigen::Matrix<double, kTangent, kTangent> At = T.transpose() * A * T;
    const Eigen::Matrix<double, kTangent, 1> bt = T.transpose() * b;
    Eigen::Matrix<double, kTangent, kTangent> R;
    Eigen::Matrix<double, kTangent, 1> z;
    // Cholesky unless a pivot is negligible (then rounding would swamp z).
    const Eigen::LLT<Eigen::Matrix<double, kTangent, kTangent>> llt(At);
    const double negligible = 1e-12 * std::max(At.diagonal().maxCoeff(), std::numeric_limits<double>::min());
    if (llt.info() == Eigen::Success && llt.matrixLLT().diagonal().cwiseAbs2().minCoeff() > negligible) {
      R = llt.matrixU();
      z = llt.matrixL().solve(bt);
    } else {  // rank-deficient: R = Lambda^1/2 V^T, z = Lambda^-1/2 V^T b on the range
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, kTangent, kTangent>> eigen(At);
      const double floor = 1e-12 * std::max(1.0, eigen.eigenvalues().cwiseAbs().maxCoeff());
      for (int i = 0; i < kTangent; ++i) {
        const double lambda = eigen.eigenvalues()[i];
        const double root = lambda > floor ? std::sqrt(lambda) : 0.0;
        R.row(i) = root * eigen.eigenvectors().col(i).transpose();
        z[i] = root > 0.0 ? eigen.eigenvectors().col(i).dot(bt) / root : 0.0;
      }
    }
    out.template head<kTangent>() = z;
    out[kTangent] = std::sqrt(std::max(0.0, ss - z.squaredNorm()));
    // Ambient Jacobians whose product with the Plus Jacobian is R: the
    // rotation's R_phi P^+ with P^+ = (P^T P)^-1 P^T, so that P^+ P = I.
    const Eigen::Matrix<double, 3, 4> P_plus = (P.transpose() * P).inverse() * P.transpose();
    if (jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, kTangent + 1, 4, Eigen::RowMajor>> J0(jacobians[0]);
      J0.template topRows<kTangent>() = R.template leftCols<3>() * P_plus;
      J0.template bottomRows<1>().setZero();
    }
    if constexpr (kWithTranslation) {
      if (jacobians[1] != nullptr) {
        Eigen::Map<Eigen::Matrix<double, kTangent + 1, 3, Eigen::RowMajor>> J1(jacobians[1]);
        J1.template topRows<kTangent>() = R.template rightCols<3>();
        J1.template bottomRows<1>().setZero();
      }
    }
    return true;
  }

  const ceres::LossFunction* loss_;
  bool square_root_;
  std::vector<const Term*> terms_;
};

// The residual blocks of one kind of term, kept across associations: cost
// function k holds term k of the current association, re-targeted by Reset
// (docs/design/solvers.md, "The residual blocks").
template <typename Functor, typename AnalyticCost>
class TermBlocks {
 public:
  TermBlocks(ceres::Problem& problem, const LossConfig& loss, bool analytic, CeresBlocks blocks, int threads,
             std::vector<double*> parameters)
      : problem_(problem),
        analytic_(analytic),
        shared_(analytic && blocks != CeresBlocks::kPerTerm),
        square_root_(analytic && blocks == CeresBlocks::kSquareRoot),
        threads_(std::max(threads, 1)),
        robust_loss_(MakeLoss(loss)),
        parameters_(std::move(parameters)) {}

  // Eq. 2's weight of every term of this kind (for the next Truncate); the
  // robust loss is inside the shared blocks, else under the weight.
  void SetWeight(double weight) {
    loss_.Reset(new ceres::ScaledLoss(shared_ ? nullptr : robust_loss_.get(), weight, ceres::DO_NOT_TAKE_OWNERSHIP),
                ceres::TAKE_OWNERSHIP);
  }

  // Term k is the one made from `args` (and, unless shared, its block is in the problem).
  template <typename... Args>
  void Set(std::size_t k, const Args&... args) {
    if (k == blocks_.size()) {
      Block block;
      if (analytic_) {
        block.analytic = new AnalyticCost(args...);
        block.cost.reset(block.analytic);
      } else {
        auto functor = std::make_unique<Functor>(args...);
        block.functor = functor.get();
        block.cost.reset(Functor::Create(std::move(functor)));  // owns the functor
      }
      blocks_.push_back(std::move(block));
    } else if (analytic_) {
      blocks_[k].analytic->Reset(args...);
    } else {
      blocks_[k].functor->Reset(args...);
    }
    Block& block = blocks_[k];
    if (!shared_ && block.id == nullptr) {
      block.id = problem_.AddResidualBlock(block.cost.get(), &loss_, parameters_.data(), int(parameters_.size()));
    }
  }

  // Makes terms [0, count) the problem's terms of this kind (blocks of
  // terms k >= count are taken out and kept for later associations).
  void Truncate(std::size_t count) {
    if (shared_) {
      Share(count);
      return;
    }
    for (std::size_t k = count; k < blocks_.size(); ++k) {
      if (blocks_[k].id == nullptr) continue;
      problem_.RemoveResidualBlock(blocks_[k].id);
      blocks_[k].id = nullptr;
    }
  }

 private:
  // The shared blocks over terms [0, count), made afresh.
  void Share(std::size_t count) {
    for (const ceres::ResidualBlockId id : shared_ids_) problem_.RemoveResidualBlock(id);
    shared_ids_.clear();
    const std::size_t per_block =
        square_root_ ? std::max<std::size_t>(1, (count + threads_ - 1) / threads_) : CeresScanProblem::kTermsPerBlock;
    for (std::size_t begin = 0, r = 0; begin < count; begin += per_block, ++r) {
      const std::size_t end = std::min(count, begin + per_block);
      if (r == shared_costs_.size()) {
        shared_costs_.push_back(std::make_unique<TermRangeCost<AnalyticCost>>(robust_loss_.get(), square_root_));
      }
      std::vector<const AnalyticCost*> terms;
      terms.reserve(end - begin);
      for (std::size_t k = begin; k < end; ++k) terms.push_back(blocks_[k].analytic);
      shared_costs_[r]->Reset(std::move(terms));
      shared_ids_.push_back(
          problem_.AddResidualBlock(shared_costs_[r].get(), &loss_, parameters_.data(), int(parameters_.size())));
    }
  }

  struct Block {
    std::unique_ptr<ceres::CostFunction> cost;
    Functor* functor = nullptr;           // autodiff: the functor `cost` owns
    AnalyticCost* analytic = nullptr;     // analytic: `cost` itself
    ceres::ResidualBlockId id = nullptr;  // null while not in the problem (always when shared)
  };
  ceres::Problem& problem_;
  bool analytic_;
  bool shared_;
  bool square_root_;
  std::size_t threads_;
  std::unique_ptr<ceres::LossFunction> robust_loss_;                 // null: trivial
  ceres::LossFunctionWrapper loss_{nullptr, ceres::TAKE_OWNERSHIP};  // the blocks' loss
  std::vector<double*> parameters_;
  std::vector<Block> blocks_;
  std::vector<std::unique_ptr<TermRangeCost<AnalyticCost>>> shared_costs_;
  std::vector<ceres::ResidualBlockId> shared_ids_;
};
}  // namespace radargauss::internal
