// SPDX-License-Identifier: BSD-3-Clause
// SLAM's keyframes and the pose graph over them (docs/design/slam.md,
// "SLAM"): each keyframe a node at the previous node's optimised pose times
// the odometry between them, joined to it by an odometry edge whose stds grow
// with the metres driven; accepted loops as edges, each followed by a solve
// of the keyframes it corrects; the paths through the graph that bound how
// far its estimate may have drifted.
#pragma once

#include <cstddef>
#include <vector>

#include "radargauss/core/types.hpp"
#include "radargauss/slam/slam_options.hpp"
#include "radargauss/solvers/pose_graph.hpp"

namespace radargauss {

struct Keyframe {
  std::size_t scan = 0;  // the scan that opened it
  double stamp = 0.0;
  SE3d odometry_pose;  // the odometry's T_world_radar at that scan
  double path = 0.0;   // m driven to it
  // Its submap, in its frame (closed keyframes; released after its search
  // when it is a revisit that no later search compares: revisit_candidates).
  std::vector<RadarPoint> points;
  std::size_t submap_points = 0;  // the submap's size, released or not
  // Place recognition's time (describe_ms: with the keyframe's map points held).
  double describe_ms = 0.0, search_ms = 0.0;
  double back_end_ms() const { return describe_ms + search_ms; }
};

class KeyframeGraph {
 public:
  explicit KeyframeGraph(const SlamOptions& options) : options_(options) {}

  // The next keyframe as the graph's next node, with its odometry edge.
  void Add(Keyframe keyframe);
  const std::vector<Keyframe>& keyframes() const { return keyframes_; }
  Keyframe& last() { return keyframes_.back(); }
  Keyframe& keyframe(std::size_t k) { return keyframes_[k]; }
  const PoseGraph& graph() const { return graph_; }

  // The metres driven from keyframe `from` to each keyframe along the
  // graph's odometry edges, loop edges crossed for free (Dijkstra).
  std::vector<double> PathsFrom(int from) const;
  // What the graph says of `query` in `candidate`, and how far it may be off.
  GraphPrior PriorOf(int candidate, int query, const std::vector<double>& paths) const;

  // An accepted loop whose path through the graph was `path` metres: its
  // edge, then a solve of the keyframes driven within that path plus
  // local_solve_margin of the query (the rest held until SolveWhole).
  void CloseLoop(int candidate, int query, const SE3d& relative, const Eigen::Matrix<double, 6, 6>& sqrt_information,
                 double path);
  // A loop edge followed by a solve of the whole graph (injected false loops).
  void AddLoopAndSolve(int candidate, int query, const SE3d& relative,
                       const Eigen::Matrix<double, 6, 6>& sqrt_information);
  // The whole graph solved, if a local solve has held part of it since the last whole one.
  void SolveWhole();

  // T_world_radar of a scan of keyframe `k` at the odometry's `odometry_pose`.
  SE3d PoseOf(std::size_t k, const SE3d& odometry_pose) const {
    return graph_.poses()[k] * (keyframes_[k].odometry_pose.Inverse() * odometry_pose);
  }

 private:
  SlamOptions options_;
  PoseGraph graph_;
  std::vector<Keyframe> keyframes_;
  bool whole_solve_due_ = false;  // a local solve since the last whole one
};

}  // namespace radargauss
