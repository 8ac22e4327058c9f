// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/slam/radar_slam.hpp"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "radargauss/core/serial_worker.hpp"

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
            .Help("a keyframe this near a place of the map already (and turned less than the angle) adds no place "
                  "and no points (0: all)"),
        RADARGAUSS_OPTION(O, "place_merge_angle", place_merge_angle_deg)
            .In(0.0, 180.0)
            .Unit("deg")
            .Help("the same, turned"),
        RADARGAUSS_OPTION(O, "hold_map_points", hold_map_points)
            .Help("hold each keyframe's static points for the map of the place (false: no map, less memory)"),
        RADARGAUSS_OPTION(O, "place_map_revisits", place_map_revisits)
            .Help("a keyframe within the merge distance of a place adds its points to the map too (memory grows with "
                  "the drive)"),
        RADARGAUSS_OPTION(O, "revisit_candidates", revisit_candidates)
            .Help("every visit of a place is a loop candidate of later searches (false: each place answered by its "
                  "newest visit within the merge distance)"),
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

RadarSlam::RadarSlam(const SlamOptions& options, const FalseLoopStudy& study, std::unique_ptr<MotionModel> motion)
    : options_(options),
      odometry_(options.odometry, std::move(motion)),
      graph_(options),
      search_(options),
      false_loops_(study, options.verification) {
  ValidateOptions(options_);
  CheckOptions(FalseLoopStudyOptionTable(), study);
  const std::size_t threads =
      std::min<std::size_t>(std::size_t(std::max(1, tbb::this_task_arena::max_concurrency())),
                            tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  if (options_.asynchronous_back_end && threads > 1) worker_ = std::make_unique<SerialWorker>();
}

RadarSlam::~RadarSlam() = default;

const OdometryStep& RadarSlam::Register(const RadarScan& scan) { return Register(scan, std::nullopt); }

const OdometryStep& RadarSlam::Register(const RadarScan& scan,
                                        const std::optional<RadarOdometry::MeasuredVelocity>& velocity) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t index = odometry_.scans();  // not steps(): it would wait for the map update behind the last
  const OdometryStep& step = odometry_.Register(scan, velocity);
  ScanTime time;
  time.front_end_ms = MillisecondsSince(start);
  const auto back_end = std::chrono::steady_clock::now();
  if (index > 0) path_ += (step.pose.translation() - odometry_.pose(index - 1).translation()).norm();
  if (!open_) {
    OpenKeyframe(index, step.pose, step.stamp);
  } else if (path_ - open_keyframe_.path >= options_.submap_distance) {
    CloseKeyframe();
    time.closed_keyframe = true;
    OpenKeyframe(index, step.pose, step.stamp);
  }
  scan_keyframe_.push_back(opened_ - 1);
  const SE3d keyframe_from_scan = open_keyframe_.odometry_pose.Inverse() * step.pose;
  if (options_.hold_map_points) open_scans_.push_back(scan);
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
  ToBackEnd([this] { graph_.SolveWhole(); });
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
  ToBackEnd([this, keyframe = open_keyframe_] { graph_.Add(keyframe); });
  open_points_.clear();
  open_scans_.clear();
  open_ = true;
}

void RadarSlam::CloseKeyframe() {
  ToBackEnd([this, submap = std::move(open_points_), scans = std::move(open_scans_)]() mutable {
    DescribeAndSearch(std::move(submap), std::move(scans));
  });
  open_points_.clear();
  open_scans_.clear();
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
  return graph_.keyframes();
}

const std::vector<LoopCandidate>& RadarSlam::candidates() const {
  Wait();
  return search_.candidates();
}

const PoseGraph& RadarSlam::graph() const {
  Wait();
  return graph_.graph();
}

void RadarSlam::DescribeAndSearch(std::vector<RadarPoint> submap, std::vector<RadarScan> scans) {
  const auto start = std::chrono::steady_clock::now();
  Keyframe& keyframe = graph_.last();
  keyframe.points = DownsampleSubmap(submap, options_.place_recognition.submap_voxel);
  keyframe.submap_points = keyframe.points.size();
  search_.AddPlace(keyframe.points);
  keyframe.describe_ms = MillisecondsSince(start);
  const auto search = std::chrono::steady_clock::now();
  const int query = int(graph_.keyframes().size()) - 1;
  const LoopSearchResult found = search_.Search(query, graph_, options_.revisit_candidates ? nullptr : &candidate_);
  if (found.accepted) {
    const LoopCandidate& loop = found.outcomes[*found.accepted];
    graph_.CloseLoop(loop.candidate, query, loop.check.relative, loop.check.sqrt_information, found.path);
  }
  if (found.searched) {
    graph_.last().search_ms = MillisecondsSince(search);
    if (const std::optional<LoopCandidate> injected = false_loops_.Inject(query, found.eligible, graph_)) {
      search_.Record(*injected);
    }
  }
  // At the poses the loop just corrected; the time counts as the description's.
  const auto hold = std::chrono::steady_clock::now();
  first_visit_.push_back(!Near(std::size_t(query), first_visit_));
  if (options_.hold_map_points && (first_visit_.back() || options_.place_map_revisits)) {
    HoldMapPoints(std::move(scans));
  }
  if (!options_.revisit_candidates) Represent(std::size_t(query));
  graph_.last().describe_ms += MillisecondsSince(hold);
}

bool RadarSlam::SamePlace(std::size_t a, std::size_t b) const {
  if (options_.place_merge_distance <= 0.0) return false;
  const SE3d &pa = graph_.graph().poses()[a], &pb = graph_.graph().poses()[b];
  return (pa.translation() - pb.translation()).norm() <= options_.place_merge_distance &&
         (pa.rotation().Inverse() * pb.rotation()).Log().norm() <= options_.place_merge_angle_deg * M_PI / 180.0;
}

bool RadarSlam::Near(std::size_t keyframe, const std::vector<bool>& among) const {
  for (std::size_t k = 0; k < keyframe; ++k) {
    if (among[k] && SamePlace(k, keyframe)) return true;
  }
  return false;
}

void RadarSlam::Represent(std::size_t keyframe) {
  candidate_.push_back(true);
  for (std::size_t k = 0; k < keyframe; ++k) {
    if (!candidate_[k] || !SamePlace(k, keyframe)) continue;
    candidate_[k] = false;  // the newest visit answers for the place
    if (!first_visit_[k]) std::vector<RadarPoint>().swap(graph_.keyframe(k).points);  // no place either: done
  }
}

void RadarSlam::HoldMapPoints(std::vector<RadarScan> scans) {
  PlaceMapPart part;
  part.keyframe = graph_.keyframes().size() - 1;
  part.first_scan = graph_.last().scan;
  part.scans.resize(scans.size());
  MapCloudOptions filter;
  filter.ego_velocity = options_.odometry.ego_velocity;
  tbb::parallel_for(std::size_t(0), scans.size(),
                    [&](std::size_t k) { part.scans[k] = StaticPointsOf(scans[k], filter); });
  place_map_.push_back(std::move(part));
}

const std::vector<bool>& RadarSlam::loop_candidates() const {
  Wait();
  return candidate_;
}

const std::vector<bool>& RadarSlam::first_visits() const {
  Wait();
  return first_visit_;
}

const std::vector<PlaceMapPart>& RadarSlam::place_map_parts() const {
  Wait();
  return place_map_;
}

std::size_t RadarSlam::place_map_bytes() const {
  std::size_t bytes = 0;
  for (const PlaceMapPart& part : place_map_parts()) {
    for (const StaticScanPoints& scan : part.scans) bytes += scan.MemoryBytes();
  }
  return bytes;
}

std::size_t RadarSlam::loops() const {
  Wait();
  const std::vector<LoopCandidate>& candidates = search_.candidates();
  return std::size_t(std::count_if(candidates.begin(), candidates.end(),
                                   [](const LoopCandidate& c) { return c.check.accepted && !c.injected; }));
}

std::size_t RadarSlam::verification_targets_built() const {
  Wait();
  return search_.verification_targets_built();
}

std::vector<SE3d> RadarSlam::Poses() const {
  Wait();
  std::vector<SE3d> poses;
  const std::vector<OdometryStep>& steps = odometry_.steps();
  poses.reserve(steps.size());
  for (std::size_t s = 0; s < steps.size(); ++s) poses.push_back(graph_.PoseOf(scan_keyframe_[s], steps[s].pose));
  return poses;
}

Trajectory RadarSlam::trajectory() const {
  Trajectory trajectory;
  const std::vector<SE3d> poses = Poses();
  for (std::size_t s = 0; s < poses.size(); ++s) trajectory.Append(odometry_.steps()[s].stamp, poses[s]);
  return trajectory;
}

}  // namespace radargauss
