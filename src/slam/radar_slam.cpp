// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/slam/radar_slam.hpp"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>

#include "radargauss/serial_worker.hpp"

namespace radargauss {

namespace {

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

const OptionTable<SlamOptions>& SlamOptionTable() {
  using O = SlamOptions;
  static const OptionTable<O> table = [] {
    OptionTable<O> t = {
        RADARGAUSS_OPTION(O, "submap_distance", submap_distance)
            .Above(0.0)
            .Unit("m")
            .Sensor()
            .Help("a keyframe every this many metres driven"),
        RADARGAUSS_OPTION(O, "min_loop_path", min_loop_path)
            .AtLeast(0.0)
            .Unit("m")
            .Help("metres driven between a loop's keyframes at least"),
        RADARGAUSS_OPTION(O, "loop_spacing", loop_spacing)
            .AtLeast(0.0)
            .Unit("m")
            .Help("after an accepted loop, keyframes within this many metres are not searched (0: every one)"),
        RADARGAUSS_OPTION(O, "odometry_translation_std", odometry_translation_std)
            .Above(0.0)
            .Unit("m")
            .Help("odometry edges: translation std"),
        RADARGAUSS_OPTION(O, "odometry_drift", odometry_drift).AtLeast(0.0).Unit("m per m").Help("and its growth"),
        RADARGAUSS_OPTION(O, "odometry_rotation_std", odometry_rotation_std_deg)
            .Above(0.0)
            .Unit("deg")
            .Help("odometry edges: rotation std"),
        RADARGAUSS_OPTION(O, "odometry_drift_deg", odometry_drift_deg)
            .AtLeast(0.0)
            .Unit("deg per m")
            .Help("and its growth"),
        RADARGAUSS_OPTION(O, "asynchronous_back_end", asynchronous_back_end)
            .Help("with more than one thread, the back end runs beside the odometry (the same results)"),
        RADARGAUSS_OPTION(O, "place_merge_distance", place_merge_distance)
            .AtLeast(0.0)
            .Unit("m")
            .Help(
                "a keyframe this near a place of the map already (and turned less than the angle) adds none (0: all)"),
        RADARGAUSS_OPTION(O, "place_merge_angle", place_merge_angle_deg)
            .In(0.0, 180.0)
            .Unit("deg")
            .Help("the same, turned"),
        RADARGAUSS_OPTION(O, "local_solve_margin", local_solve_margin)
            .AtLeast(0.0)
            .Unit("m")
            .Help("a loop re-solves the keyframes within its path through the graph plus this (0: the whole graph)"),
    };
    AppendPlaceSearchRows(t);
    AppendNested(
        t, PoseGraphOptionTable(), +[](O & o) -> auto& { return o.graph; }, "graph");
    return t;
  }();
  return table;
}

const OptionTable<FalseLoopStudy>& FalseLoopStudyOptionTable() {
  using O = FalseLoopStudy;
  static const OptionTable<O> table = {
      RADARGAUSS_OPTION(O, "false_loop_rate", rate)
          .In(0.0, 1.0)
          .Study()
          .Help("robustness studies: the share of keyframes given an injected false loop (0: none)"),
      RADARGAUSS_OPTION(O, "false_loop_seed", seed).Study().Help("seed of the injected false loops"),
  };
  return table;
}

void ValidateOptions(const SlamOptions& o) {
  CheckOptions(SlamOptionTable(), o);
  ValidateOptions(o.verification);
}

RadarSlam::RadarSlam(const SlamOptions& options, const FalseLoopStudy& study)
    : options_(options),
      study_(study),
      odometry_(options.odometry),
      places_(options.place_recognition),
      targets_(options.verification.kept_targets),
      false_loops_(study.seed) {
  ValidateOptions(options_);
  CheckOptions(FalseLoopStudyOptionTable(), study_);
  const std::size_t threads =
      std::min<std::size_t>(std::size_t(std::max(1, tbb::this_task_arena::max_concurrency())),
                            tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  if (options_.asynchronous_back_end && threads > 1) worker_ = std::make_unique<SerialWorker>();
}

RadarSlam::~RadarSlam() = default;

void RadarSlam::UseImu(const RadarInertialOptions& options, const SE3d& radar_from_imu, std::vector<ImuSample> imu) {
  inertial_ = std::make_unique<InertialFusion>(options, radar_from_imu, std::move(imu));
  inertial_->Attach(odometry_);
}

const OdometryStep& RadarSlam::Register(const RadarScan& scan) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t index = odometry_.steps().size();
  if (inertial_) inertial_->BeforeScan(odometry_, scan.timestamp);
  const OdometryStep& step = odometry_.Register(scan);
  if (inertial_) inertial_->AfterScan();
  ScanTime time;
  time.front_end_ms = MillisecondsSince(start);
  const auto back_end = std::chrono::steady_clock::now();
  if (index > 0) path_ += (step.pose.translation() - odometry_.steps()[index - 1].pose.translation()).norm();
  if (!open_) {
    OpenKeyframe(index, step.pose, step.stamp);
  } else if (path_ - open_keyframe_.path >= options_.submap_distance) {
    CloseKeyframe();
    time.closed_keyframe = true;
    OpenKeyframe(index, step.pose, step.stamp);
  }
  scan_keyframe_.push_back(opened_ - 1);
  const SE3d keyframe_from_scan = open_keyframe_.odometry_pose.Inverse() * step.pose;
  for (const std::size_t i : odometry_.last_static_points()) {
    RadarPoint point = scan.points[i];
    point.position = keyframe_from_scan * point.position;
    point.doppler = 0.0;
    open_points_.push_back(point);
  }
  time.back_end_ms = MillisecondsSince(back_end);
  scan_times_.push_back(time);
  return step;
}

void RadarSlam::Finish() {
  const auto start = std::chrono::steady_clock::now();
  const bool closing = open_;
  if (open_) CloseKeyframe();
  ToBackEnd([this] {
    if (whole_solve_due_) graph_.Optimize(options_.graph);
    whole_solve_due_ = false;
  });
  Wait();
  if (scan_times_.empty()) return;
  scan_times_.back().back_end_ms += MillisecondsSince(start);
  scan_times_.back().closed_keyframe = scan_times_.back().closed_keyframe || closing;
}

void RadarSlam::OpenKeyframe(std::size_t scan, const SE3d& pose, double stamp) {
  open_keyframe_ = Keyframe();
  open_keyframe_.scan = scan;
  open_keyframe_.stamp = stamp;
  open_keyframe_.odometry_pose = pose;
  open_keyframe_.path = path_;
  ++opened_;
  ToBackEnd([this, keyframe = open_keyframe_] { AddKeyframe(keyframe); });
  open_points_.clear();
  open_ = true;
}

void RadarSlam::CloseKeyframe() {
  ToBackEnd([this, submap = std::move(open_points_)]() mutable { DescribeAndSearch(std::move(submap)); });
  open_points_.clear();
  open_ = false;
}

void RadarSlam::ToBackEnd(std::function<void()> work) {
  if (worker_) {
    worker_->Post(std::move(work));
  } else {
    work();
  }
}

void RadarSlam::Wait() const {
  if (worker_) worker_->Wait();
}

const std::vector<Keyframe>& RadarSlam::keyframes() const {
  Wait();
  return keyframes_;
}

const std::vector<LoopCandidate>& RadarSlam::candidates() const {
  Wait();
  return candidates_;
}

const PoseGraph& RadarSlam::graph() const {
  Wait();
  return graph_;
}

// The keyframe's graph node at the previous node's optimised pose times the
// odometry between them, and their odometry edge.
void RadarSlam::AddKeyframe(Keyframe keyframe) {
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

void RadarSlam::DescribeAndSearch(std::vector<RadarPoint> submap) {
  const auto start = std::chrono::steady_clock::now();
  Keyframe& keyframe = keyframes_.back();
  keyframe.points = DownsampleSubmap(submap, options_.place_recognition.submap_voxel);
  places_.Add(places_.Describe(keyframe.points));
  keyframe.describe_ms = MillisecondsSince(start);
  SearchLoops(int(keyframes_.size()) - 1);
}

// Cheapest checks first: the descriptor's distance (close or not), each
// yaw's bird's-eye start against the graph (farther than the consistency
// bound plus verify_start_margin: refused), the best consistent start's
// overlap (below verify_min_overlap: refused), then the Gaussian
// match of the verify_budget best overlapping, in that order, as one thread
// would: the first that verifies is accepted and those after it are not
// matched. The matches run in waves of as many as there are threads
// (against the same graph, which changes only on acceptance), so that the
// accepted loop and every outcome are those of one thread; a wave may match
// some that one thread would not have reached.
void RadarSlam::SearchLoops(int query) {
  const auto start = std::chrono::steady_clock::now();
  if (last_loop_path_ >= 0.0 && options_.loop_spacing > 0.0 &&
      keyframes_[std::size_t(query)].path - last_loop_path_ < options_.loop_spacing) {
    return;
  }
  std::vector<int> eligible;  // far enough back along the path
  for (int c = 0; c < query && keyframes_[query].path - keyframes_[c].path >= options_.min_loop_path; ++c) {
    eligible.push_back(c);
  }
  std::vector<PlaceMatch> ranked = places_.Rank(places_.place(std::size_t(query)), eligible);
  const std::vector<double> paths = PathsThroughGraph(query);
  const LoopVerificationOptions& verification = options_.verification;
  std::vector<LoopCandidate> outcomes(ranked.size());
  std::vector<double> overlaps(ranked.size(), 0.0);
  std::vector<std::size_t> to_match;  // close, consistent and overlapping, best overlap first
  for (std::size_t i = 0; i < ranked.size(); ++i) {
    LoopCandidate& c = outcomes[i];
    c.query = query;
    c.candidate = ranked[i].candidate;
    c.distance = ranked[i].distance;
    c.yaw = ranked[i].yaws.front();
    char reason[80];
    if (!ranked[i].close) {
      std::snprintf(reason, sizeof(reason), "descriptor distance %.3f", ranked[i].distance);
      c.check.reason = reason;
      continue;
    }
    // The yaws whose start may end consistent with the graph, and their best overlap.
    const GraphPrior prior = PriorOf(c.candidate, query, paths);
    const std::vector<BirdsEyeStart> starts =
        BirdsEyeStarts(keyframes_[query].points, keyframes_[c.candidate].points, ranked[i].yaws, verification);
    std::vector<double> yaws;
    for (const BirdsEyeStart& start : starts) {
      if (!CorrectGraph(start.pose(), prior, verification, verification.start_margin, verification.start_margin_deg)
               .consistent) {
        continue;
      }
      yaws.push_back(start.yaw);
      overlaps[i] = std::max(overlaps[i], start.overlap);
    }
    c.check.overlap = overlaps[i];
    if (yaws.empty()) {
      const GraphCorrection off = CorrectGraph(starts.front().pose(), prior, verification);
      c.check.correction = off.translation;
      c.check.correction_deg = off.rotation_deg;
      std::snprintf(reason, sizeof(reason), "start inconsistent with the graph: %.1f m, %.1f deg", off.translation,
                    off.rotation_deg);
      c.check.reason = reason;
      continue;
    }
    ranked[i].yaws = std::move(yaws);
    if (overlaps[i] < verification.min_overlap) {
      std::snprintf(reason, sizeof(reason), "bird's-eye overlap %.2f", overlaps[i]);
      c.check.reason = reason;
      continue;
    }
    to_match.push_back(i);
  }
  std::stable_sort(to_match.begin(), to_match.end(),
                   [&](std::size_t a, std::size_t b) { return overlaps[a] > overlaps[b]; });
  const std::size_t budget = options_.verification.budget;
  for (std::size_t m = budget > 0 ? budget : to_match.size(); m < to_match.size(); ++m) {
    outcomes[to_match[m]].check.reason = "past the verification budget";
  }
  if (budget > 0 && to_match.size() > budget) to_match.resize(budget);
  const std::size_t wave = std::size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
  bool accepted = false;
  for (std::size_t m = 0; m < to_match.size(); m += wave) {
    const std::vector<std::size_t> members(to_match.begin() + std::ptrdiff_t(m),
                                           to_match.begin() + std::ptrdiff_t(std::min(to_match.size(), m + wave)));
    if (accepted) {
      for (const std::size_t i : members) outcomes[i].check.reason = "another candidate was accepted";
      continue;
    }
    const std::vector<LoopCandidate> results = VerifyWave(query, ranked, members, paths);
    for (std::size_t k = 0; k < members.size(); ++k) {
      LoopCandidate& c = outcomes[members[k]];
      if (accepted) {
        c.check.reason = "another candidate was accepted";
        continue;
      }
      c = results[k];
      if (c.check.accepted) {
        graph_.AddLoop(c.candidate, query, c.check.relative, c.check.sqrt_information);
        SolveAfterLoop(query, paths[std::size_t(c.candidate)]);
        last_loop_path_ = keyframes_[std::size_t(query)].path;
        accepted = true;
      }
    }
  }
  candidates_.insert(candidates_.end(), outcomes.begin(), outcomes.end());
  keyframes_[query].search_ms = MillisecondsSince(start);
  if (study_.rate > 0.0 && !eligible.empty()) InjectFalseLoop(query, eligible);
}

// The loop corrects the drift of the `path` metres it closes: the keyframes
// driven within that plus the margin move, the rest stays for Finish's
// whole solve (docs/design.md, "SLAM").
void RadarSlam::SolveAfterLoop(int query, double path) {
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

void RadarSlam::InjectFalseLoop(int query, const std::vector<int>& eligible) {
  if (std::uniform_real_distribution<double>(0.0, 1.0)(false_loops_) >= study_.rate) return;
  LoopCandidate loop;
  loop.query = query;
  loop.candidate = eligible[std::uniform_int_distribution<std::size_t>(0, eligible.size() - 1)(false_loops_)];
  loop.injected = true;
  loop.check.accepted = true;
  loop.check.reason = "injected false loop";
  Eigen::Matrix<double, 6, 1> weights;
  weights << Eigen::Vector3d::Constant(1.0 / options_.verification.translation_floor_std),
      Eigen::Vector3d::Constant(180.0 / M_PI / options_.verification.rotation_floor_std_deg);
  loop.check.sqrt_information = weights.asDiagonal();
  graph_.AddLoop(loop.candidate, query, SE3d(), loop.check.sqrt_information);
  graph_.Optimize(options_.graph);
  candidates_.push_back(loop);
}

std::vector<LoopCandidate> RadarSlam::VerifyWave(int query, const std::vector<PlaceMatch>& ranked,
                                                 const std::vector<std::size_t>& members,
                                                 const std::vector<double>& paths) {
  std::vector<int> indices;
  std::vector<const std::vector<RadarPoint>*> points;
  for (const std::size_t j : members) {
    indices.push_back(ranked[j].candidate);
    points.push_back(&keyframes_[ranked[j].candidate].points);
  }
  const std::vector<std::shared_ptr<const VerificationTarget>> targets =
      targets_.GetAll(indices, points, options_.verification);
  std::vector<LoopCandidate> results(members.size());
  tbb::parallel_for(std::size_t(0), members.size(), [&](std::size_t m) {
    const PlaceMatch& match = ranked[members[m]];
    results[m] = Verify(query, match, *targets[m], PriorOf(match.candidate, query, paths));
  });
  return results;
}

GraphPrior RadarSlam::PriorOf(int candidate, int query, const std::vector<double>& paths) const {
  return {graph_.poses()[candidate].Inverse() * graph_.poses()[query], paths[candidate]};
}

LoopCandidate RadarSlam::Verify(int query, const PlaceMatch& match, const VerificationTarget& target,
                                const GraphPrior& prior) const {
  LoopCandidate result;
  result.query = query;
  result.candidate = match.candidate;
  result.distance = match.distance;
  result.verified = true;
  for (const double yaw : match.yaws) {
    LoopCheck check = VerifyLoop(keyframes_[query].points, target, yaw, prior, options_.verification);
    if (check.accepted || yaw == match.yaws.front() || check.associated > result.check.associated) {
      result.check = std::move(check);
      result.yaw = yaw;
    }
    if (result.check.accepted) break;
  }
  return result;
}

std::vector<double> RadarSlam::PathsThroughGraph(int from) const {
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

std::size_t RadarSlam::loops() const {
  Wait();
  return std::size_t(std::count_if(candidates_.begin(), candidates_.end(),
                                   [](const LoopCandidate& c) { return c.check.accepted && !c.injected; }));
}

std::size_t RadarSlam::verification_targets_built() const {
  Wait();
  return targets_.built();
}

std::vector<SE3d> RadarSlam::Poses() const {
  Wait();
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
