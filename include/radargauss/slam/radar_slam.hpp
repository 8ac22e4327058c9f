// SPDX-License-Identifier: BSD-3-Clause
// Radar SLAM (docs/design/slam.md, "SLAM"): radar odometry as the front end;
// every submap_distance metres a keyframe whose submap holds the static
// points of the scans until the next, in its own frame. A closed submap is
// described (Scan Context or the Radon descriptor), its nearest keyframes by
// the yaw-invariant key farther back than min_loop_path are compared and
// verified (slam/loop_search.hpp), and an accepted loop enters the pose
// graph (slam/keyframe_graph.hpp), which is optimised again from its current
// estimate. Each scan follows its keyframe. RadarSlam holds the front end,
// the back end's parts and the order of their calls: with more than one
// thread the back end (all of the above but the odometry) runs beside the
// odometry on its own thread, in the keyframes' order; nothing of it feeds
// back into the odometry, so the results are those of one thread.
//
//   RadarSlam slam(options);
//   for (const RadarScan& scan : sequence.scans) slam.Register(scan);
//   slam.Finish();
//   WriteTum(path, slam.trajectory());
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "radargauss/map/map_cloud.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/slam/keyframe_graph.hpp"
#include "radargauss/slam/loop_search.hpp"
#include "radargauss/slam/slam_options.hpp"

namespace radargauss {

// One scan's time in Register (ms): the front end (the odometry with its
// motion model) and the back end (closing a keyframe: its description, the place
// search, verification and graph solves; only handing it over when the back
// end is asynchronous); Finish's goes to the last scan.
struct ScanTime {
  double front_end_ms = 0.0, back_end_ms = 0.0;
  bool closed_keyframe = false;  // the back end described and searched a keyframe
  double total_ms() const { return front_end_ms + back_end_ms; }
};

class SerialWorker;

// A keyframe's part of the map of the place: the static points of its scans
// (StaticPointsOf with the odometry's Doppler filter), from scan first_scan on.
struct PlaceMapPart {
  std::size_t keyframe = 0, first_scan = 0;
  std::vector<StaticScanPoints> scans;
};

class RadarSlam {
 public:
  // `motion`: the front end's motion model (odometry/motion_model.hpp; null:
  // constant velocity), as RadarOdometry's.
  explicit RadarSlam(const SlamOptions& options = {}, const FalseLoopStudy& study = {},
                     std::unique_ptr<MotionModel> motion = nullptr);
  ~RadarSlam();
  RadarSlam(const RadarSlam&) = delete;  // the back end's thread holds `this`
  RadarSlam& operator=(const RadarSlam&) = delete;

  // As RadarOdometry::Register; a keyframe that closes is described and searched.
  const OdometryStep& Register(const RadarScan& scan);
  // The same for a scan without Doppler whose velocity was measured apart
  // (a rig's frame, odometry/rig_odometry.hpp).
  const OdometryStep& Register(const RadarScan& scan, const std::optional<RadarOdometry::MeasuredVelocity>& velocity);
  // Closes the last keyframe (described and searched) and waits for the back end.
  void Finish();
  // Whether the back end runs on its own thread (asynchronous_back_end and
  // more than one thread allowed when constructed).
  bool asynchronous() const { return worker_ != nullptr; }

  const RadarOdometry& odometry() const { return odometry_; }
  // The front end's inertial window; null when its motion model is another.
  const InertialMotion* inertial() const { return InertialMotionOf(odometry_); }
  // The back end's state: each waits until the keyframes handed over so far
  // are done; what they return holds until the next Register or Finish.
  const std::vector<Keyframe>& keyframes() const;
  const std::vector<LoopCandidate>& candidates() const;
  const PoseGraph& graph() const;
  const std::vector<ScanTime>& scan_times() const { return scan_times_; }
  const SlamOptions& options() const { return options_; }
  std::size_t loops() const;  // accepted (injected false loops not counted)
  // Verification targets built (each kept one is reused: verify_kept_targets).
  std::size_t verification_targets_built() const;
  // Per closed keyframe: whether it is the first visit of its place (no
  // earlier first visit within place_merge_distance and angle at the poses
  // of its closing; every one when the distance is 0). The first visits are
  // the map's places and hold its points.
  const std::vector<bool>& first_visits() const;
  // Per closed keyframe, without revisit_candidates: whether it is its
  // place's loop candidate now (the newest visit within the merge distance
  // of the others); empty with revisit_candidates (every one is).
  const std::vector<bool>& loop_candidates() const;
  // The keyframes' parts of the map of the place (hold_map_points), in
  // keyframe order, and the bytes their points hold.
  const std::vector<PlaceMapPart>& place_map_parts() const;
  std::size_t place_map_bytes() const;
  // T_world_radar of every scan: its keyframe's optimised pose times the odometry since.
  std::vector<SE3d> Poses() const;
  Trajectory trajectory() const;

 private:
  // The front end's side: what the back end is handed, in order.
  void OpenKeyframe(std::size_t scan, const SE3d& pose, double stamp);
  void CloseKeyframe();
  void ToBackEnd(std::function<void()> work);
  void Wait() const;  // rethrows what the back end threw
  // The back end's side: the closed keyframe's place, its loop search, the
  // accepted loop into the graph, and the study's false loop.
  void DescribeAndSearch(std::vector<RadarPoint> submap, std::vector<RadarScan> scans);
  // Whether keyframes a and b lie within place_merge_distance and angle of
  // each other at the graph's poses now (never with the distance 0).
  bool SamePlace(std::size_t a, std::size_t b) const;
  // Whether the keyframe is the SamePlace of one of `among` before it.
  bool Near(std::size_t keyframe, const std::vector<bool>& among) const;
  // Without revisit_candidates: the closed keyframe becomes its place's
  // loop candidate, in place of the candidates within the merge distance.
  void Represent(std::size_t keyframe);
  // Holds the closed keyframe's static points (a PlaceMapPart).
  void HoldMapPoints(std::vector<RadarScan> scans);

  SlamOptions options_;
  // The front end.
  RadarOdometry odometry_;
  std::vector<std::size_t> scan_keyframe_;  // per scan
  std::vector<ScanTime> scan_times_;        // per scan
  Keyframe open_keyframe_;                  // the open keyframe (no points)
  std::vector<RadarPoint> open_points_;     // its submap so far
  std::vector<RadarScan> open_scans_;       // its scans (hold_map_points)
  std::size_t opened_ = 0;                  // keyframes opened
  double path_ = 0.0;
  bool open_ = false;
  // The back end.
  KeyframeGraph graph_;
  LoopSearch search_;
  FalseLoops false_loops_;
  std::vector<PlaceMapPart> place_map_;
  std::vector<bool> candidate_;    // per closed keyframe: a loop candidate of later searches (revisit_candidates false)
  std::vector<bool> first_visit_;  // per closed keyframe: no earlier first visit within the merge distance
  std::unique_ptr<SerialWorker> worker_;  // the back end's thread; null: in Register
};

// Keyframe and loop counts, place recognition's time per keyframe (median),
// the last solve's.
struct SlamSummary {
  std::size_t keyframes = 0, compared = 0, verified = 0, loops = 0, injected = 0;  // loops: accepted, not injected
  double describe_ms = 0.0, search_ms = 0.0;                                       // medians per keyframe
  // Per keyframe, the back end's work (description and search): median, p99 and maximum.
  double keyframe_median_ms = 0.0, keyframe_p99_ms = 0.0, keyframe_max_ms = 0.0;
  bool asynchronous = false;
  // Per scan (ScanTime): median, p90, p99 and maximum of the total and of the back end.
  double total_median_ms = 0.0, total_p90_ms = 0.0, total_p99_ms = 0.0, total_max_ms = 0.0;
  double back_end_median_ms = 0.0, back_end_p90_ms = 0.0, back_end_p99_ms = 0.0, back_end_max_ms = 0.0;
};
SlamSummary Summarise(const RadarSlam& slam);

// The map of the place: build-map's estimator (the odometry map's Gaussian
// and RCS options, its Doppler filter) over the points the slam holds
// (place_map_parts) at their scans' optimised poses, with the first visits
// (first_visits) as places at their optimised poses. Throws DataError
// without held points (hold_map_points false, or no static point).
GaussianMap BuildPlaceMap(const RadarSlam& slam);
// The same over every one of `scans`, the ones registered, in order (as
// BuildPlaceMap(slam) with place_map_revisits).
GaussianMap BuildPlaceMap(const std::vector<RadarScan>& scans, const RadarSlam& slam);

// Writes slam.tum (each scan's optimised T_world_radar), keyframes.csv,
// loops.csv, per_scan.csv (each scan's time: total, front end, back end) and
// slam.json into `dir` (created), each file whole or not at all.
void WriteSlam(const std::string& dir, const RadarSlam& slam);

}  // namespace radargauss
