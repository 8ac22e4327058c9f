// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/pose_graph.hpp"

#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/sized_cost_function.h>
#include <ceres/solver.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>

#include "radargauss/lie/manifold.hpp"
#include "radargauss/core/names.hpp"
#include "radargauss/residuals/relative_pose_residual.hpp"
#include "radargauss/residuals/robust_loss.hpp"
#include "radargauss/solvers/pose_graph_initialization.hpp"

namespace radargauss {

namespace {
constexpr NamedValue<LoopRejection> kLoopRejectionNames[] = {{LoopRejection::kLoss, "loss"},
                                                             {LoopRejection::kSwitchable, "switchable"},
                                                             {LoopRejection::kGraduated, "graduated"}};
}  // namespace

std::string ToString(LoopRejection rejection) { return NameOf(kLoopRejectionNames, rejection); }
LoopRejection LoopRejectionFromString(const std::string& name) {
  return ValueNamed(kLoopRejectionNames, name, "loop rejection");
}
std::vector<std::string> LoopRejectionNames() { return NamesOf(kLoopRejectionNames); }

namespace {
constexpr NamedValue<GraphInitialization> kInitializationNames[] = {{GraphInitialization::kCurrent, "current"},
                                                                    {GraphInitialization::kChordal, "chordal"}};
}  // namespace

std::string ToString(GraphInitialization initialization) { return NameOf(kInitializationNames, initialization); }
GraphInitialization GraphInitializationFromString(const std::string& name) {
  return ValueNamed(kInitializationNames, name, "graph initialization");
}
std::vector<std::string> GraphInitializationNames() { return NamesOf(kInitializationNames); }

namespace {

// A loop edge's relative-pose residual times its switch s (switchable
// constraints): blocks R_i, t_i, R_j, t_j, s; d(s r)/ds = r.
class SwitchedCost final : public ceres::SizedCostFunction<6, 4, 3, 4, 3, 1> {
 public:
  explicit SwitchedCost(ceres::CostFunction* edge) : edge_(edge) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    if (!edge_->Evaluate(parameters, residuals, jacobians)) return false;
    const double s = parameters[4][0];
    if (jacobians != nullptr) {
      const int sizes[4] = {6 * 4, 6 * 3, 6 * 4, 6 * 3};
      for (int b = 0; b < 4; ++b) {
        if (jacobians[b] == nullptr) continue;
        for (int k = 0; k < sizes[b]; ++k) jacobians[b][k] *= s;
      }
      if (jacobians[4] != nullptr) {
        for (int k = 0; k < 6; ++k) jacobians[4][k] = residuals[k];
      }
    }
    for (int k = 0; k < 6; ++k) residuals[k] *= s;
    return true;
  }

 private:
  std::unique_ptr<ceres::CostFunction> edge_;
};

// The switch's prior: (1 - s) / sigma.
class SwitchPrior final : public ceres::SizedCostFunction<1, 1> {
 public:
  explicit SwitchPrior(double sigma) : inverse_sigma_(1.0 / sigma) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    residuals[0] = (1.0 - parameters[0][0]) * inverse_sigma_;
    if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][0] = -inverse_sigma_;
    return true;
  }

 private:
  const double inverse_sigma_;
};

ceres::CostFunction* EdgeCost(const PoseGraphEdge& edge, JacobianMode jacobians) {
  if (jacobians == JacobianMode::kAutoDiff) return RelativePoseResidual::Create(edge.measured, edge.sqrt_information);
  return new RelativePoseCostFunction(edge.measured, edge.sqrt_information);
}

// Levenberg-Marquardt on the sparse normal equations, by SuiteSparse's Cholesky.
ceres::Solver::Options SolverOptions(const PoseGraphOptions& options) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver_options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.num_threads = options.threads;
  solver_options.logging_type = ceres::SILENT;
  // From the chordal start, in the basin, nearly Gauss-Newton: Ceres's first
  // radius (1e4) would damp it into tens of small steps.
  if (options.initialization == GraphInitialization::kChordal) solver_options.initial_trust_region_radius = 1e8;
  return solver_options;
}

bool Finite(const SE3d& pose) {
  return pose.translation().allFinite() && pose.rotation().quaternion().coeffs().allFinite();
}

}  // namespace

const OptionTable<PoseGraphOptions>& PoseGraphOptionTable() {
  using O = PoseGraphOptions;
  static const OptionTable<O> table = {
      RADARGAUSS_CHOICE(O, "loop_rejection", loop_rejection, LoopRejectionNames(), LoopRejectionFromString)
          .Help("loop edges: loss, switchable or graduated"),
      RADARGAUSS_CHOICE(O, "loop_loss", loop_loss.type, LossNames(), LossTypeFromString)
          .Help("loss of the loop edges (loop rejection 'loss'; graduated: its scale)"),
      RADARGAUSS_OPTION(O, "loop_loss_scale", loop_loss.scale).Above(0.0).Help("scale of the loop loss"),
      RADARGAUSS_OPTION(O, "switch_prior_std", switch_prior_std).Above(0.0).Help("switchable: std of a switch's prior"),
      RADARGAUSS_OPTION(O, "graduation_factor", graduation_factor).Above(1.0).Help("graduated: mu's divisor per round"),
      RADARGAUSS_CHOICE(O, "graph_initialization", initialization, GraphInitializationNames(),
                        GraphInitializationFromString)
          .Help(
              "where each solve starts: current (the last optimum and the odometry) or chordal (trusting every loop)"),
      RADARGAUSS_CHOICE(O, "graph_jacobians", jacobians, JacobianModeNames(), JacobianModeFromString)
          .Help("pose graph: closed-form Jacobians or Jets"),
      RADARGAUSS_OPTION(O, "graph_max_iterations", max_iterations).AtLeast(1).Help("pose graph: iterations per solve"),
      RADARGAUSS_OPTION(O, "graph_function_tolerance", function_tolerance)
          .In(1e-16, 0.1)
          .Help("pose graph: a solve stops when the cost changes by less than this share"),
      RADARGAUSS_OPTION(O, "graph_threads", threads).In(1, 1024).Help("pose graph: Ceres's threads"),
  };
  return table;
}

int PoseGraph::AddKeyframe(const SE3d& pose) {
  if (!Finite(pose)) {
    throw std::invalid_argument("pose graph: keyframe pose is not finite");
  }
  poses_.push_back(pose);
  return int(poses_.size()) - 1;
}

void PoseGraph::Check(int from, int to, const SE3d& measured, const Eigen::Matrix<double, 6, 6>& W) const {
  const int n = int(poses_.size());
  if (from < 0 || to < 0 || from >= n || to >= n || from == to) {
    throw std::invalid_argument("pose graph: edge " + std::to_string(from) + " -> " + std::to_string(to) +
                                " needs two different keyframes of 0.." + std::to_string(n - 1));
  }
  if (!Finite(measured) || !W.allFinite()) {
    throw std::invalid_argument("pose graph: edge measurement or information is not finite");
  }
}

void PoseGraph::AddOdometry(int from, int to, const SE3d& measured, const Eigen::Matrix<double, 6, 6>& W) {
  Check(from, to, measured, W);
  edges_.push_back({from, to, measured, W, false});
}

int PoseGraph::AddLoop(int from, int to, const SE3d& measured, const Eigen::Matrix<double, 6, 6>& W) {
  Check(from, to, measured, W);
  edges_.push_back({from, to, measured, W, true});
  switches_.push_back(1.0);
  loop_weights_.push_back(1.0);
  return int(switches_.size()) - 1;
}

// The graph as a Ceres problem: the parameter blocks, and per loop edge its
// residual block and the loss wrapper that kLoss and kGraduated set.
struct PoseGraph::Problem {
  std::vector<Eigen::Vector4d> rotations;
  std::vector<Eigen::Vector3d> translations;
  SO3Manifold so3;
  std::unique_ptr<ceres::Problem> problem;
  std::vector<ceres::ResidualBlockId> loop_blocks;
  std::vector<ceres::LossFunctionWrapper*> loop_losses;  // owned by the problem
  std::vector<std::size_t> loops;                        // the loop of each block (loop_weights' index)
  std::vector<bool> used;                                // per keyframe: in the problem

  // |r|^2 of each loop edge at the current parameters, without its loss.
  std::vector<double> LoopSquaredNorms() const {
    std::vector<double> norms;
    for (const ceres::ResidualBlockId id : loop_blocks) {
      double cost = 0.0;
      Eigen::Matrix<double, 6, 1> r;
      problem->EvaluateResidualBlock(id, false, &cost, r.data(), nullptr);
      norms.push_back(r.squaredNorm());
    }
    return norms;
  }
};

std::unique_ptr<PoseGraph::Problem> PoseGraph::Build(const PoseGraphOptions& options, int first_free) {
  auto graph = std::make_unique<Problem>();
  const std::size_t n = poses_.size();
  for (std::size_t k = 0; k < n; ++k) {
    graph->rotations.push_back(poses_[k].rotation().quaternion().coeffs());
    graph->translations.push_back(poses_[k].translation());
  }
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  graph->problem = std::make_unique<ceres::Problem>(problem_options);
  ceres::Problem& problem = *graph->problem;
  // The free keyframes in order, a held one when an edge reaches it (constant).
  graph->used.assign(n, false);
  const auto use = [&](std::size_t k) {
    if (graph->used[k]) return;
    graph->used[k] = true;
    problem.AddParameterBlock(graph->rotations[k].data(), 4, &graph->so3);
    problem.AddParameterBlock(graph->translations[k].data(), 3);
    if (k < std::size_t(first_free)) {
      problem.SetParameterBlockConstant(graph->rotations[k].data());
      problem.SetParameterBlockConstant(graph->translations[k].data());
    }
  };
  for (std::size_t k = std::size_t(first_free); k < n; ++k) use(k);
  std::size_t loop = 0;
  for (const PoseGraphEdge& edge : edges_) {
    if (std::max(edge.from, edge.to) < first_free) {
      loop += edge.loop;
      continue;
    }
    use(std::size_t(edge.from));
    use(std::size_t(edge.to));
    std::vector<double*> blocks = {graph->rotations[edge.from].data(), graph->translations[edge.from].data(),
                                   graph->rotations[edge.to].data(), graph->translations[edge.to].data()};
    ceres::CostFunction* cost = EdgeCost(edge, options.jacobians);
    if (!edge.loop) {
      problem.AddResidualBlock(cost, nullptr, blocks);
      continue;
    }
    if (options.loop_rejection == LoopRejection::kSwitchable) {
      double* s = &switches_[loop];
      blocks.push_back(s);
      graph->loop_blocks.push_back(problem.AddResidualBlock(new SwitchedCost(cost), nullptr, blocks));
      problem.AddResidualBlock(new SwitchPrior(options.switch_prior_std), nullptr, s);
      problem.SetParameterLowerBound(s, 0, 0.0);
      problem.SetParameterUpperBound(s, 0, 1.0);
    } else {
      auto* loss = new ceres::LossFunctionWrapper(
          options.loop_rejection == LoopRejection::kLoss ? MakeLoss(options.loop_loss) : nullptr,
          ceres::TAKE_OWNERSHIP);
      graph->loop_losses.push_back(loss);
      graph->loop_blocks.push_back(problem.AddResidualBlock(cost, loss, blocks));
    }
    graph->loops.push_back(loop);
    ++loop;
  }
  if (graph->used[0]) {  // the gauge
    problem.SetParameterBlockConstant(graph->rotations[0].data());
    problem.SetParameterBlockConstant(graph->translations[0].data());
  }
  return graph;
}

// Graduated non-convexity with Geman-McClure (Yang et al. 2020): from the
// quadratic solution, rounds of weighted least squares with the weights
// (mu a^2 / (s + mu a^2))^2, mu from 2 max(s) / a^2 down to 1 by the factor.
void PoseGraph::Graduate(Problem& graph, const PoseGraphOptions& options, PoseGraphSummary& summary) {
  const double a2 = options.loop_loss.scale * options.loop_loss.scale;
  std::vector<double> norms = graph.LoopSquaredNorms();
  double mu = 1.0;
  for (const double s : norms) mu = std::max(mu, 2.0 * s / a2);
  while (true) {
    for (std::size_t l = 0; l < norms.size(); ++l) {
      const double weight = mu * a2 / (norms[l] + mu * a2);
      double& loop_weight = loop_weights_[graph.loops[l]];
      loop_weight = weight * weight;
      graph.loop_losses[l]->Reset(new ceres::ScaledLoss(nullptr, loop_weight, ceres::TAKE_OWNERSHIP),
                                  ceres::TAKE_OWNERSHIP);
    }
    ceres::Solver::Summary round;
    ceres::Solve(SolverOptions(options), graph.problem.get(), &round);
    summary.iterations += int(round.iterations.size()) - 1;
    summary.final_cost = round.final_cost;
    summary.converged = round.termination_type == ceres::CONVERGENCE;
    ++summary.solves;
    if (mu <= 1.0) return;
    mu = std::max(1.0, mu / options.graduation_factor);
    norms = graph.LoopSquaredNorms();
  }
}

PoseGraphSummary PoseGraph::Optimize(const PoseGraphOptions& options) { return Optimize(options, 0); }

PoseGraphSummary PoseGraph::Optimize(const PoseGraphOptions& options, int first_free) {
  CheckOptions(PoseGraphOptionTable(), options);
  if (first_free < 0 || first_free > int(poses_.size())) {
    throw std::invalid_argument("the first free keyframe must be one of the graph's");
  }
  if (first_free > 0 && options.initialization == GraphInitialization::kChordal) {
    throw std::invalid_argument("a chordal start solves the whole graph");
  }
  const auto start = std::chrono::steady_clock::now();
  PoseGraphSummary summary;
  if (poses_.empty() || first_free == int(poses_.size())) {
    summary.converged = true;
    summary.message = "no free keyframe";
    return summary;
  }
  if (options.initialization == GraphInitialization::kChordal) poses_ = ChordalInitialization(poses_, edges_);
  const std::unique_ptr<Problem> graph = Build(options, first_free);
  ceres::Solver::Summary first;  // kGraduated: the quadratic solution it starts from
  ceres::Solve(SolverOptions(options), graph->problem.get(), &first);
  summary.converged = first.termination_type == ceres::CONVERGENCE;
  summary.iterations = int(first.iterations.size()) - 1;
  summary.initial_cost = first.initial_cost;
  summary.final_cost = first.final_cost;
  summary.message = first.message;
  if (options.loop_rejection == LoopRejection::kGraduated) Graduate(*graph, options, summary);

  for (std::size_t k = std::size_t(first_free); k < poses_.size(); ++k) {
    poses_[k] = SE3d(SO3d::FromXyzw(graph->rotations[k].data()), graph->translations[k]);
  }
  if (options.loop_rejection != LoopRejection::kGraduated) {
    const std::vector<double> norms = graph->LoopSquaredNorms();
    const std::unique_ptr<ceres::LossFunction> loss(MakeLoss(options.loop_loss));
    for (std::size_t l = 0; l < norms.size(); ++l) {
      double rho[3] = {0.0, 1.0, 0.0};
      if (loss) loss->Evaluate(norms[l], rho);
      const std::size_t loop = graph->loops[l];
      loop_weights_[loop] = options.loop_rejection == LoopRejection::kSwitchable ? switches_[loop] : rho[1];
    }
  }
  summary.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace radargauss
