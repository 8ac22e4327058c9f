// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/slam/keyframe_graph.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

namespace radargauss {

void KeyframeGraph::Add(Keyframe keyframe) {
  if (keyframes_.empty()) {
    graph_.AddKeyframe(keyframe.odometry_pose);
  } else {
    const Keyframe& last = keyframes_.back();
    const SE3d measured = last.odometry_pose.Inverse() * keyframe.odometry_pose;
    const int from = int(keyframes_.size()) - 1;
    const int to = graph_.AddKeyframe(graph_.poses()[from] * measured);
    const double driven = keyframe.path - last.path;
    const double translation_std = options_.odometry_translation_std + options_.odometry_drift * driven;
    const double rotation_std =
        (options_.odometry_rotation_std_deg + options_.odometry_drift_deg * driven) * M_PI / 180.0;
    Eigen::Matrix<double, 6, 1> weights;
    weights << Eigen::Vector3d::Constant(1.0 / translation_std), Eigen::Vector3d::Constant(1.0 / rotation_std);
    graph_.AddOdometry(from, to, measured, weights.asDiagonal());
  }
  keyframes_.push_back(std::move(keyframe));
}

std::vector<double> KeyframeGraph::PathsFrom(int from) const {
  // Dijkstra over the keyframes: odometry edges weigh the metres driven, loop edges nothing.
  std::vector<std::vector<int>> loops(keyframes_.size());
  for (const PoseGraphEdge& edge : graph_.edges()) {
    if (!edge.loop) continue;
    loops[edge.from].push_back(edge.to);
    loops[edge.to].push_back(edge.from);
  }
  std::vector<double> distance(keyframes_.size(), std::numeric_limits<double>::infinity());
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  distance[from] = 0.0;
  queue.emplace(0.0, from);
  while (!queue.empty()) {
    const double d = queue.top().first;
    const int k = queue.top().second;
    queue.pop();
    if (d > distance[k]) continue;
    const auto relax = [&](int next, double weight) {
      if (d + weight < distance[next]) queue.emplace(distance[next] = d + weight, next);
    };
    if (k > 0) relax(k - 1, keyframes_[k].path - keyframes_[k - 1].path);
    if (k + 1 < int(keyframes_.size())) relax(k + 1, keyframes_[k + 1].path - keyframes_[k].path);
    for (const int next : loops[k]) relax(next, 0.0);
  }
  return distance;
}

GraphPrior KeyframeGraph::PriorOf(int candidate, int query, const std::vector<double>& paths) const {
  return {graph_.poses()[candidate].Inverse() * graph_.poses()[query], paths[candidate]};
}

// The loop corrects the drift of the `path` metres it closes: the keyframes
// driven within that plus the margin move, the rest stays for SolveWhole
// (docs/design/slam.md, "SLAM").
void KeyframeGraph::CloseLoop(int candidate, int query, const SE3d& relative,
                              const Eigen::Matrix<double, 6, 6>& sqrt_information, double path) {
  graph_.AddLoop(candidate, query, relative, sqrt_information);
  int first_free = 0;
  if (options_.local_solve_margin > 0.0) {
    const double reach = path + options_.local_solve_margin;
    first_free = query;
    while (first_free > 0 &&
           keyframes_[std::size_t(query)].path - keyframes_[std::size_t(first_free - 1)].path <= reach) {
      --first_free;
    }
  }
  graph_.Optimize(options_.graph, first_free);
  whole_solve_due_ = whole_solve_due_ || first_free > 0;
}

void KeyframeGraph::AddLoopAndSolve(int candidate, int query, const SE3d& relative,
                                    const Eigen::Matrix<double, 6, 6>& sqrt_information) {
  graph_.AddLoop(candidate, query, relative, sqrt_information);
  graph_.Optimize(options_.graph);
}

void KeyframeGraph::SolveWhole() {
  if (whole_solve_due_) graph_.Optimize(options_.graph);
  whole_solve_due_ = false;
}

}  // namespace radargauss
