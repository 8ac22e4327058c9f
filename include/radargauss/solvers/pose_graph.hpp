// SPDX-License-Identifier: BSD-3-Clause
// A pose graph over keyframes (docs/design/solvers.md, "The pose graph"): odometry
// edges between consecutive keyframes and loop edges between revisits, each
// a relative-pose term (residuals/relative_pose_residual.hpp) weighted by
// the square root of its match's information. Loop edges take a robust loss
// of residuals/loss.hpp (DCS among them), switchable constraints or graduated
// non-convexity; the first keyframe is fixed (the gauge). Solved by Ceres's
// Levenberg-Marquardt with sparse Cholesky (SuiteSparse).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/lie/se3.hpp"
#include "radargauss/residuals/loss.hpp"
#include "radargauss/solvers/scan_matcher.hpp"

namespace radargauss {

// How loop edges are kept from pulling the graph apart when they are false.
enum class LoopRejection {
  kLoss,        // loop_loss on s = |r|^2 (DCS, Cauchy, Huber, ... or trivial: none)
  kSwitchable,  // switchable constraints (Suenderhauf and Protzel 2012)
  kGraduated,   // graduated non-convexity to Geman-McClure of scale loop_loss.scale (Yang et al. 2020)
};
std::string ToString(LoopRejection rejection);                   // "loss", "switchable", "graduated"
LoopRejection LoopRejectionFromString(const std::string& name);  // throws std::invalid_argument
std::vector<std::string> LoopRejectionNames();

// Where Levenberg-Marquardt starts.
enum class GraphInitialization {
  kCurrent,  // the current poses (the last optimum plus odometry, in SLAM)
  // ChordalInitialization (pose_graph_initialization.hpp): rotations, then
  // translations, from the edges alone, then LM nearly Gauss-Newton (first
  // radius 1e8). For a graph solved once from composed odometry; it trusts
  // every loop, so a false loop bends the start of any robust loss.
  kChordal,
};
std::string ToString(GraphInitialization initialization);                    // "current", "chordal"
GraphInitialization GraphInitializationFromString(const std::string& name);  // throws std::invalid_argument
std::vector<std::string> GraphInitializationNames();

struct PoseGraphOptions {
  LoopRejection loop_rejection = LoopRejection::kGraduated;
  // kLoss: the loss of every loop edge on its whitened squared norm (odometry
  // edges are quadratic); kGraduated: its scale is Geman-McClure's a.
  LossConfig loop_loss{LossType::kGemanMcClure, 3.0};
  // kSwitchable: sigma of the prior (1 - s) / sigma on each switch; the
  // literature's 1 drops true loops from a drifted start (docs/design.md).
  double switch_prior_std = 0.1;
  double graduation_factor = 1.4;  // kGraduated: mu's divisor per round
  GraphInitialization initialization = GraphInitialization::kCurrent;
  JacobianMode jacobians = JacobianMode::kAnalytic;
  int max_iterations = 100;  // per solve
  // Levenberg-Marquardt stops when the cost changes by less than this share.
  double function_tolerance = 1e-6;
  int threads = 1;
};

// Its options (options.hpp).
const OptionTable<PoseGraphOptions>& PoseGraphOptionTable();

struct PoseGraphSummary {
  bool converged = false;
  int iterations = 0;  // Levenberg-Marquardt's, over every solve
  int solves = 1;      // graduated non-convexity: one per round
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double time_ms = 0.0;
  std::string message;  // Ceres's
};

struct PoseGraphEdge {
  int from = 0;                                                                            // i
  int to = 0;                                                                              // j
  SE3d measured;                                                                           // Z_ij: frame i from frame j
  Eigen::Matrix<double, 6, 6> sqrt_information = Eigen::Matrix<double, 6, 6>::Identity();  // W
  bool loop = false;
};

class PoseGraph {
 public:
  // A keyframe at its initial estimate (world from keyframe); returns its index.
  int AddKeyframe(const SE3d& pose);
  // Throws std::invalid_argument on an unknown keyframe, i == j or a
  // non-finite measurement or information.
  void AddOdometry(int from, int to, const SE3d& measured, const Eigen::Matrix<double, 6, 6>& sqrt_information);
  // Returns the loop's index (loop_weights' order).
  int AddLoop(int from, int to, const SE3d& measured, const Eigen::Matrix<double, 6, 6>& sqrt_information);

  // From the current estimate; the poses become the optimum.
  PoseGraphSummary Optimize(const PoseGraphOptions& options);
  // The same over the keyframes from `first_free` on, those before held where
  // they are: only the edges that reach a free keyframe enter, and only their
  // loops' weights change. The cost of the part a loop changes, not the map's.
  PoseGraphSummary Optimize(const PoseGraphOptions& options, int first_free);

  const std::vector<SE3d>& poses() const { return poses_; }
  const std::vector<PoseGraphEdge>& edges() const { return edges_; }
  // Per loop edge, how much it counts after the last Optimize: the switch,
  // the last round's weight, or the loss's rho'(s) at the optimum (1: fully,
  // near 0: rejected).
  const std::vector<double>& loop_weights() const { return loop_weights_; }

 private:
  struct Problem;
  std::unique_ptr<Problem> Build(const PoseGraphOptions& options, int first_free);
  void Graduate(Problem& graph, const PoseGraphOptions& options, PoseGraphSummary& summary);
  void Check(int from, int to, const SE3d& measured, const Eigen::Matrix<double, 6, 6>& sqrt_information) const;

  std::vector<SE3d> poses_;
  std::vector<PoseGraphEdge> edges_;
  std::vector<double> switches_;  // per loop edge (switchable constraints)
  std::vector<double> loop_weights_;
};

}  // namespace radargauss
