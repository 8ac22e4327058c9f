// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/slam/radar_slam.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>
#include <unordered_set>

#include "radargauss/names.hpp"
#include "radargauss/voxel_grid.hpp"

namespace radargauss {

namespace {

constexpr NamedValue<PlaceDescriptorKind> kDescriptorNames[] = {{PlaceDescriptorKind::kScanContext, "scan-context"},
                                                                 {PlaceDescriptorKind::kRadon, "radon"}};

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The first point of each voxel, in arrival order.
std::vector<RadarPoint> Downsampled(const std::vector<RadarPoint>& points, double voxel) {
  std::unordered_set<std::int64_t> seen;
  std::vector<RadarPoint> kept;
  for (const RadarPoint& point : points) {
    if (seen.insert(PackVoxelKey(VoxelOf(point.position, voxel))).second) kept.push_back(point);
  }
  return kept;
}

}  // namespace

std::string ToString(PlaceDescriptorKind kind) { return NameOf(kDescriptorNames, kind); }
PlaceDescriptorKind PlaceDescriptorKindFromString(const std::string& name) {
  return ValueNamed(kDescriptorNames, name, "place descriptor");
}
std::vector<std::string> PlaceDescriptorKindNames() { return NamesOf(kDescriptorNames); }

void ValidateOptions(const SlamOptions& o) {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("slam: ") + what);
  };
  ValidateOptions(o.odometry);
  ValidateOptions(o.verification);
  ValidateScanContextOptions(o.scan_context);
  ValidateRadonOptions(o.radon);
  require(o.submap_distance > 0.0 && std::isfinite(o.submap_distance), "submap_distance must be positive");
  require(o.submap_voxel > 0.0 && std::isfinite(o.submap_voxel), "submap_voxel must be positive");
  require(o.min_loop_path >= 0.0, "min_loop_path must be >= 0");
  require(o.candidates >= 1, "candidates must be >= 1");
  require(o.max_descriptor_distance >= 0.0 && o.max_descriptor_distance <= 1.0,
          "max_descriptor_distance must be in [0, 1]");
  require(o.odometry_translation_std > 0.0 && o.odometry_rotation_std_deg > 0.0, "odometry stds must be positive");
  require(o.odometry_drift >= 0.0 && o.odometry_drift_deg >= 0.0, "odometry drifts must be >= 0");
}

RadarSlam::RadarSlam(const SlamOptions& options) : options_(options), odometry_(options.odometry) {
  ValidateOptions(options_);
}

const OdometryStep& RadarSlam::Register(const RadarScan& scan) {
  const std::size_t index = odometry_.steps().size();
  const OdometryStep& step = odometry_.Register(scan);
  if (index > 0) path_ += (step.pose.translation() - odometry_.steps()[index - 1].pose.translation()).norm();
  if (!open_) {
    OpenKeyframe(index, step.pose, step.stamp);
  } else if (path_ - keyframes_.back().path >= options_.submap_distance) {
    CloseKeyframe();
    OpenKeyframe(index, step.pose, step.stamp);
  }
  scan_keyframe_.push_back(keyframes_.size() - 1);
  const SE3d keyframe_from_scan = keyframes_.back().odometry_pose.Inverse() * step.pose;
  for (const std::size_t i : odometry_.last_static_points()) {
    RadarPoint point = scan.points[i];
    point.position = keyframe_from_scan * point.position;
    point.doppler = 0.0;
    open_points_.push_back(point);
  }
  return step;
}

void RadarSlam::Finish() {
  if (open_) CloseKeyframe();
}

void RadarSlam::OpenKeyframe(std::size_t scan, const SE3d& pose, double stamp) {
  Keyframe keyframe;
  keyframe.scan = scan;
  keyframe.stamp = stamp;
  keyframe.odometry_pose = pose;
  keyframe.path = path_;
  if (keyframes_.empty()) {
    graph_.AddKeyframe(pose);
  } else {
    const Keyframe& last = keyframes_.back();
    const SE3d measured = last.odometry_pose.Inverse() * pose;
    const int from = int(keyframes_.size()) - 1;
    const int to = graph_.AddKeyframe(graph_.poses()[from] * measured);
    const double driven = path_ - last.path;
    const double translation_std = options_.odometry_translation_std + options_.odometry_drift * driven;
    const double rotation_std =
        (options_.odometry_rotation_std_deg + options_.odometry_drift_deg * driven) * M_PI / 180.0;
    Eigen::Matrix<double, 6, 1> weights;
    weights << Eigen::Vector3d::Constant(1.0 / translation_std), Eigen::Vector3d::Constant(1.0 / rotation_std);
    graph_.AddOdometry(from, to, measured, weights.asDiagonal());
  }
  keyframes_.push_back(std::move(keyframe));
  open_points_.clear();
  open_ = true;
}

void RadarSlam::CloseKeyframe() {
  const auto start = std::chrono::steady_clock::now();
  Keyframe& keyframe = keyframes_.back();
  keyframe.points = Downsampled(open_points_, options_.submap_voxel);
  open_points_.clear();
  if (options_.descriptor == PlaceDescriptorKind::kScanContext) {
    keyframe.scan_context = MakeScanContext(keyframe.points, options_.scan_context);
  } else {
    keyframe.radon = MakeRadonDescriptor(keyframe.points, options_.radon);
  }
  keyframe.describe_ms = MillisecondsSince(start);
  open_ = false;
  SearchLoops(int(keyframes_.size()) - 1);
}

void RadarSlam::SearchLoops(int query) {
  const auto start = std::chrono::steady_clock::now();
  const Keyframe& q = keyframes_[query];
  const bool scan_context = options_.descriptor == PlaceDescriptorKind::kScanContext;
  const Eigen::VectorXd& query_key = scan_context ? q.scan_context.ring_key : q.radon.key;
  // The nearest keys among the keyframes far enough back.
  std::vector<std::pair<double, int>> nearest;
  for (int c = 0; c < query; ++c) {
    if (q.path - keyframes_[c].path < options_.min_loop_path) break;  // in path order
    const Eigen::VectorXd& key = scan_context ? keyframes_[c].scan_context.ring_key : keyframes_[c].radon.key;
    nearest.emplace_back((query_key - key).norm(), c);
  }
  const std::size_t kept = std::min<std::size_t>(nearest.size(), std::size_t(options_.candidates));
  std::partial_sort(nearest.begin(), nearest.begin() + kept, nearest.end());
  nearest.resize(kept);
  // The full descriptors, best first; verified until one is accepted.
  std::vector<LoopCandidate> compared;
  for (const auto& [key_distance, c] : nearest) {
    LoopCandidate candidate;
    candidate.query = query;
    candidate.candidate = c;
    if (scan_context) {
      const ScanContextMatch match = CompareScanContexts(q.scan_context, keyframes_[c].scan_context, options_.scan_context);
      candidate.distance = match.distance;
      candidate.yaw = match.yaw;
    } else {
      const RadonMatch match = CompareRadonDescriptors(q.radon, keyframes_[c].radon, options_.radon);
      candidate.distance = match.distance;
      candidate.yaw = match.yaw;
    }
    compared.push_back(candidate);
  }
  std::stable_sort(compared.begin(), compared.end(),
                   [](const LoopCandidate& a, const LoopCandidate& b) { return a.distance < b.distance; });
  bool accepted = false;
  for (LoopCandidate& candidate : compared) {
    char reason[64];
    if (accepted) {
      candidate.check.reason = "another candidate was accepted";
    } else if (candidate.distance > options_.max_descriptor_distance) {
      std::snprintf(reason, sizeof(reason), "descriptor distance %.3f", candidate.distance);
      candidate.check.reason = reason;
    } else {
      candidate = Verify(query, candidate.candidate, candidate.distance, candidate.yaw);
      if (candidate.check.accepted) {
        graph_.AddLoop(candidate.candidate, query, candidate.check.relative, candidate.check.sqrt_information);
        graph_.Optimize(options_.graph);
        accepted = true;
      }
    }
    candidates_.push_back(candidate);
  }
  keyframes_[query].search_ms = MillisecondsSince(start);
}

LoopCandidate RadarSlam::Verify(int query, int candidate, double distance, double yaw) const {
  LoopCandidate result;
  result.query = query;
  result.candidate = candidate;
  result.distance = distance;
  result.yaw = yaw;
  result.verified = true;
  const SE3d expected = graph_.poses()[candidate].Inverse() * graph_.poses()[query];
  const double path = PathThroughGraph(candidate, query);
  // The Radon descriptor's yaw is known up to pi: both are tried.
  std::vector<double> yaws = {yaw};
  if (options_.descriptor == PlaceDescriptorKind::kRadon) yaws.push_back(yaw - M_PI);
  for (const double tried : yaws) {
    LoopCheck check = VerifyLoop(keyframes_[query].points, keyframes_[candidate].points, tried, expected, path,
                                 options_.verification);
    if (check.accepted || tried == yaws.front() || check.associated > result.check.associated) {
      result.check = std::move(check);
      result.yaw = tried;
    }
    if (result.check.accepted) break;
  }
  return result;
}

double RadarSlam::PathThroughGraph(int from, int to) const {
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
    const auto [d, k] = queue.top();
    queue.pop();
    if (k == to) return d;
    if (d > distance[k]) continue;
    const auto relax = [&](int next, double weight) {
      if (d + weight < distance[next]) queue.emplace(distance[next] = d + weight, next);
    };
    if (k > 0) relax(k - 1, keyframes_[k].path - keyframes_[k - 1].path);
    if (k + 1 < int(keyframes_.size())) relax(k + 1, keyframes_[k + 1].path - keyframes_[k].path);
    for (const int next : loops[k]) relax(next, 0.0);
  }
  return distance[to];
}

std::size_t RadarSlam::loops() const {
  return std::size_t(std::count_if(candidates_.begin(), candidates_.end(),
                                   [](const LoopCandidate& c) { return c.check.accepted; }));
}

std::vector<SE3d> RadarSlam::Poses() const {
  std::vector<SE3d> poses;
  const std::vector<OdometryStep>& steps = odometry_.steps();
  poses.reserve(steps.size());
  for (std::size_t s = 0; s < steps.size(); ++s) {
    const std::size_t k = scan_keyframe_[s];
    poses.push_back(graph_.poses()[k] * (keyframes_[k].odometry_pose.Inverse() * steps[s].pose));
  }
  return poses;
}

Trajectory RadarSlam::trajectory() const {
  Trajectory trajectory;
  const std::vector<SE3d> poses = Poses();
  for (std::size_t s = 0; s < poses.size(); ++s) trajectory.Append(odometry_.steps()[s].stamp, poses[s]);
  return trajectory;
}

}  // namespace radargauss
