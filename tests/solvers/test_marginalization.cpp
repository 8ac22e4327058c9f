// SPDX-License-Identifier: BSD-3-Clause
// Marginalisation by the Schur complement (docs/design/solvers.md, "The sliding
// window"): on a linear-Gaussian chain the prior left by the first states
// puts the rest at the whole problem's optimum, from any linearisation
// point; on a rotation its Jacobian agrees with central differences.
#include <gtest/gtest.h>

#include <ceres/normal_prior.h>
#include <ceres/sized_cost_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <memory>
#include <random>

#include "radargauss/lie/manifold.hpp"
#include "radargauss/solvers/marginalization.hpp"
#include "support/cost_function_checks.hpp"

namespace radargauss {
namespace {

using Vector3 = Eigen::Vector3d;

// r = W (x_j - x_i - d): a linear edge between two 3-vectors.
class LinearEdge final : public ceres::SizedCostFunction<3, 3, 3> {
 public:
  LinearEdge(const Vector3& d, const Eigen::Matrix3d& W) : d_(d), W_(W) {}
  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    Eigen::Map<Vector3> r(residuals);
    r = W_ * (Eigen::Map<const Vector3>(x[1]) - Eigen::Map<const Vector3>(x[0]) - d_);
    using M = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
    for (int b = 0; jacobians != nullptr && b < 2; ++b) {
      if (jacobians[b] == nullptr) continue;
      Eigen::Map<M> J(jacobians[b]);
      J = b == 0 ? Eigen::Matrix3d(-W_) : W_;
    }
    return true;
  }

 private:
  Vector3 d_;
  Eigen::Matrix3d W_;
};

Eigen::Matrix3d RandomWeight(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix3d W = Eigen::Matrix3d::Identity() * 2.0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) W(r, c) += 0.5 * u(rng);
  return W;
}

// A chain x0 - x1 - ... - x5 with a prior on x0, edges between neighbours,
// an edge x0 - x2 (so that x0 touches two kept states) and absolute
// measurements of x3 and x5.
struct Chain {
  std::vector<Vector3> x = std::vector<Vector3>(6, Vector3::Zero());
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  std::vector<std::pair<int, int>> edges;  // (i, j); j < 0: a unary cost on i

  explicit Chain(std::mt19937& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    const auto add_unary = [&](int i) {
      const Eigen::Matrix3d W = RandomWeight(rng);
      costs.emplace_back(new ceres::NormalPrior(W, Vector3(n(rng), n(rng), n(rng))));
      edges.push_back({i, -1});
    };
    add_unary(0);
    for (int i = 0; i + 1 < 6; ++i) {
      costs.emplace_back(new LinearEdge(Vector3(1.0 + n(rng), n(rng), 0.1 * n(rng)), RandomWeight(rng)));
      edges.push_back({i, i + 1});
    }
    costs.emplace_back(new LinearEdge(Vector3(2.0, 0.5, 0.0), RandomWeight(rng)));
    edges.push_back({0, 2});
    add_unary(3);
    add_unary(5);
  }

  // Adds every cost touching no state below `first` (not owned by the problem).
  std::vector<ceres::ResidualBlockId> AddTo(ceres::Problem& problem, int first, bool touching_first_only = false) {
    std::vector<ceres::ResidualBlockId> ids;
    for (std::size_t k = 0; k < costs.size(); ++k) {
      const auto [i, j] = edges[k];
      if (i < first || (j >= 0 && j < first)) continue;
      if (touching_first_only && i != first && j != first) continue;
      if (j < 0) {
        ids.push_back(problem.AddResidualBlock(costs[k].get(), nullptr, x[i].data()));
      } else {
        ids.push_back(problem.AddResidualBlock(costs[k].get(), nullptr, x[i].data(), x[j].data()));
      }
    }
    return ids;
  }
};

ceres::Problem::Options NotOwning() {
  ceres::Problem::Options options;
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return options;
}

void SolveExactly(ceres::Problem& problem) {
  ceres::Solver::Options options;
  options.function_tolerance = 0.0;
  options.gradient_tolerance = 0.0;
  options.parameter_tolerance = 1e-15;
  options.max_num_iterations = 20;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
}

// The chain solved whole; its states are left there.
std::vector<Vector3> WholeOptimum(Chain& chain) {
  ceres::Problem whole(NotOwning());
  chain.AddTo(whole, 0);
  SolveExactly(whole);
  return chain.x;
}

TEST(Marginalization, PriorReproducesTheWholeProblemsOptimumOnALinearChain) {
  std::mt19937 rng(5);
  Chain chain(rng);
  const std::vector<Vector3> batch = WholeOptimum(chain);

  // Marginalise x0 and then x1, each linearised away from the optimum.
  std::normal_distribution<double> n(0.0, 1.0);
  for (Vector3& x : chain.x) x += Vector3(n(rng), n(rng), n(rng));
  std::shared_ptr<MarginalizationPrior> prior;
  for (int leaving = 0; leaving < 2; ++leaving) {
    ceres::Problem problem(NotOwning());
    std::vector<ceres::ResidualBlockId> factors = chain.AddTo(problem, leaving, true);
    if (prior) factors.push_back(problem.AddResidualBlock(prior.get(), nullptr, prior->parameter_blocks()));
    std::vector<double*> kept = {chain.x[leaving + 1].data()};
    if (leaving == 0) kept.push_back(chain.x[2].data());
    prior = Marginalize(problem, factors, {chain.x[leaving].data()}, kept);
    ASSERT_NE(prior, nullptr);
  }
  EXPECT_EQ(prior->parameter_blocks().size(), 1u);  // x2 alone: x0's edge to x2 went with x1

  ceres::Problem rest(NotOwning());
  chain.AddTo(rest, 2);
  rest.AddResidualBlock(prior.get(), nullptr, prior->parameter_blocks());
  SolveExactly(rest);
  for (int i = 2; i < 6; ++i) EXPECT_LT((chain.x[i] - batch[i]).norm(), 1e-9) << "x" << i;
}

TEST(Marginalization, DroppingInsteadMovesTheOptimum) {
  std::mt19937 rng(5);
  Chain chain(rng);
  const std::vector<Vector3> batch = WholeOptimum(chain);
  ceres::Problem rest(NotOwning());
  chain.AddTo(rest, 2);
  SolveExactly(rest);
  EXPECT_GT((chain.x[2] - batch[2]).norm(), 1e-3);
}

// A prior on a rotation: its Jacobian (through the manifold's Minus) against
// central differences along the tangent, and zero residual change at x0.
TEST(Marginalization, PriorOnARotationHasTheManifoldsJacobian) {
  Eigen::Vector4d q = SO3d::Exp(Vector3(0.3, -0.2, 1.0)).quaternion().coeffs();
  const Eigen::Matrix3d W = Eigen::Vector3d(10.0, 20.0, 5.0).asDiagonal();
  const SO3Manifold so3;
  MarginalizationPrior::Block block{nullptr, q, &so3, 3};
  MarginalizationPrior prior({block}, W, Vector3(0.1, 0.0, -0.2));
  const SO3d moved = SO3d::FromXyzw(q.data()) * SO3d::Exp(Vector3(0.01, -0.02, 0.005));
  Eigen::Vector4d x = moved.quaternion().coeffs();
  std::vector<Eigen::MatrixXd> J;
  const Eigen::VectorXd r = EvaluateWithJacobians(prior, {x.data()}, J);
  EXPECT_LT((r - (Vector3(0.1, 0.0, -0.2) + W * Vector3(0.01, -0.02, 0.005))).norm(), 1e-12);
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> P;
  so3.PlusJacobian(x.data(), P.data());
  const Eigen::MatrixXd tangent = J[0] * P;
  const Eigen::MatrixXd numeric = testing::NumericJacobian(
      [&](const Eigen::VectorXd& d) {
        Eigen::Vector4d y;
        so3.Plus(x.data(), d.data(), y.data());
        Eigen::VectorXd out(3);
        const double* blocks[] = {y.data()};
        prior.Evaluate(blocks, out.data(), nullptr);
        return out;
      },
      Eigen::VectorXd::Zero(3));
  EXPECT_LT(Relative(tangent, numeric), 0.02);  // first order: Jr^-1 of a 0.02 rad step is I to 1 %
  // At the linearisation itself the Jacobian along the tangent is W.
  std::vector<Eigen::MatrixXd> J0;
  EvaluateWithJacobians(prior, {q.data()}, J0);
  so3.PlusJacobian(q.data(), P.data());
  EXPECT_LT(Relative(J0[0] * P, W), 1e-12);
}

}  // namespace
}  // namespace radargauss
