// SPDX-License-Identifier: BSD-3-Clause
// Radar SLAM (docs/design/slam.md, "SLAM"): radar odometry as the front end;
// every submap_distance metres a keyframe whose submap holds the static
// points of the scans until the next, in its own frame. A closed submap is
// described (Scan Context or the Radon descriptor), its nearest keyframes by
// the yaw-invariant key farther back than min_loop_path are compared and
// verified (slam/loop_verification.hpp), and an accepted loop enters the
// pose graph, which is optimised again from its current estimate. Each scan
// follows its keyframe. With more than one thread the back end (all of the
// above but the odometry) runs beside the odometry on its own thread, in the
// keyframes' order: nothing of it feeds back into the odometry, so the
// results are those of one thread.
//
//   RadarSlam slam(options);
//   for (const RadarScan& scan : sequence.scans) slam.Register(scan);
//   slam.Finish();
//   WriteTum(path, slam.trajectory());
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/slam/loop_verification.hpp"
#include "radargauss/slam/place_recognition.hpp"
#include "radargauss/solvers/pose_graph.hpp"

namespace radargauss {

struct SlamOptions {
  OdometryOptions odometry;
  double submap_distance = 10.0;  // m driven per keyframe
  PlaceRecognitionOptions place_recognition;
  double min_loop_path = 150.0;  // m driven between a loop's keyframes (the active map closes shorter ones)
  // After an accepted loop, the keyframes closed within this many metres
  // driven are not searched: the loop has just corrected them. 0: every one.
  double loop_spacing = 0.0;  // m
  LoopVerificationOptions verification;
  PoseGraphOptions graph;
  // The odometry edges' stds: floor plus drift per metre driven between keyframes.
  double odometry_translation_std = 0.05;  // m
  double odometry_drift = 0.02;            // m per m
  double odometry_rotation_std_deg = 0.1;
  double odometry_drift_deg = 0.02;  // deg per m
  // With more than one thread, the back end on its own thread (same results).
  bool asynchronous_back_end = true;
  // An accepted loop re-solves the keyframes driven within its path through
  // the graph plus this margin of the query, the rest held; Finish solves
  // the whole graph. 0: every solve is of the whole graph.
  double local_solve_margin = 100.0;  // m
  // The map of the place keeps a keyframe as a place unless a place already
  // kept lies within this many metres and degrees of its optimised pose: a
  // revisit adds no place. 0 (the default): every keyframe is a place.
  double place_merge_distance = 0.0;  // m
  double place_merge_angle_deg = 45.0;
};

// Robustness studies, apart from what a user sets: after each keyframe's
// search, with probability `rate` a false loop to a keyframe chosen at
// random (at least min_loop_path back) claiming the two coincide (identity,
// at the loop floors' weight) goes into the graph, recorded in candidates()
// as injected. 0: none.
struct FalseLoopStudy {
  double rate = 0.0;
  std::uint32_t seed = 1;
};
const OptionTable<FalseLoopStudy>& FalseLoopStudyOptionTable();

// Throws std::invalid_argument naming the bad option.
// The rows a search for places shares, SLAM's and relocalisation's alike:
// the odometry's, place recognition's and the loop verification's
// (verify_*), of a struct that holds the three under those names.
template <typename Options>
void AppendPlaceSearchRows(OptionTable<Options>& table) {
  AppendNested(
      table, OdometryOptionTable(), +[](Options & o) -> auto& { return o.odometry; }, "odometry");
  AppendNested(
      table, PlaceRecognitionOptionTable(), +[](Options & o) -> auto& { return o.place_recognition; },
      "place_recognition");
  AppendNested(
      table, LoopVerificationOptionTable(), +[](Options & o) -> auto& { return o.verification; }, "verification",
      "verify_");
}

// Its options (options.hpp): its own, the odometry's, place recognition's,
// the loop verification's (verify_*) and the pose graph's.
const OptionTable<SlamOptions>& SlamOptionTable();
void ValidateOptions(const SlamOptions& options);

struct Keyframe {
  std::size_t scan = 0;  // the scan that opened it
  double stamp = 0.0;
  SE3d odometry_pose;                         // the odometry's T_world_radar at that scan
  double path = 0.0;                          // m driven to it
  std::vector<RadarPoint> points;             // its submap, in its frame (closed keyframes)
  double describe_ms = 0.0, search_ms = 0.0;  // place recognition's time
  double back_end_ms() const { return describe_ms + search_ms; }
};

// One scan's time in Register (ms): the front end (the odometry, the IMU's
// fusion) and the back end (closing a keyframe: its description, the place
// search, verification and graph solves; only handing it over when the back
// end is asynchronous); Finish's goes to the last scan.
struct ScanTime {
  double front_end_ms = 0.0, back_end_ms = 0.0;
  bool closed_keyframe = false;  // the back end described and searched a keyframe
  double total_ms() const { return front_end_ms + back_end_ms; }
};

// A compared pair: the descriptor's verdict, then the verification's.
struct LoopCandidate {
  int query = 0, candidate = 0;  // keyframes
  double distance = 1.0;         // the descriptor's
  double yaw = 0.0;              // rad: the descriptor's, of the query in the candidate
  bool verified = false;         // passed to verification
  bool injected = false;         // a false loop of FalseLoopStudy, not a candidate
  LoopCheck check;               // check.accepted: in the graph
};

class SerialWorker;

class RadarSlam {
 public:
  explicit RadarSlam(const SlamOptions& options = {}, const FalseLoopStudy& study = {});
  ~RadarSlam();
  RadarSlam(const RadarSlam&) = delete;  // the back end's thread holds `this`
  RadarSlam& operator=(const RadarSlam&) = delete;

  // From the next scan on, the odometry is radar-inertial (odometry/radar_inertial.hpp):
  // the IMU's samples on the scans' clock, T_radar_imu, the window's options.
  void UseImu(const RadarInertialOptions& options, const SE3d& radar_from_imu, std::vector<ImuSample> imu);
  // As RadarOdometry::Register; a keyframe that closes is described and searched.
  const OdometryStep& Register(const RadarScan& scan);
  // Closes the last keyframe (described and searched) and waits for the back end.
  void Finish();
  // Whether the back end runs on its own thread (asynchronous_back_end and
  // more than one thread allowed when constructed).
  bool asynchronous() const { return worker_ != nullptr; }

  const RadarOdometry& odometry() const { return odometry_; }
  const InertialFusion* inertial() const { return inertial_.get(); }  // null without UseImu
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
  // T_world_radar of every scan: its keyframe's optimised pose times the odometry since.
  std::vector<SE3d> Poses() const;
  Trajectory trajectory() const;

 private:
  // The front end's side: what the back end is handed, in order.
  void OpenKeyframe(std::size_t scan, const SE3d& pose, double stamp);
  void CloseKeyframe();
  void ToBackEnd(std::function<void()> work);
  void Wait() const;  // rethrows what the back end threw
  // The back end's side.
  void AddKeyframe(Keyframe keyframe);
  void DescribeAndSearch(std::vector<RadarPoint> submap);
  // After a loop whose path through the graph was `path` metres.
  void SolveAfterLoop(int query, double path);
  void SearchLoops(int query);
  void InjectFalseLoop(int query, const std::vector<int>& eligible);
  // The Gaussian matches of ranked[members], in parallel.
  std::vector<LoopCandidate> VerifyWave(int query, const std::vector<PlaceMatch>& ranked,
                                        const std::vector<std::size_t>& members, const std::vector<double>& paths);
  LoopCandidate Verify(int query, const PlaceMatch& match, const VerificationTarget& target,
                       const GraphPrior& prior) const;
  // The metres driven from keyframe `from` to each keyframe along the graph's
  // odometry edges, loop edges crossed for free: how far the graph's estimate
  // may have drifted.
  std::vector<double> PathsThroughGraph(int from) const;
  GraphPrior PriorOf(int candidate, int query, const std::vector<double>& paths) const;

  SlamOptions options_;
  FalseLoopStudy study_;
  // The front end.
  RadarOdometry odometry_;
  std::unique_ptr<InertialFusion> inertial_;
  std::vector<std::size_t> scan_keyframe_;  // per scan
  std::vector<ScanTime> scan_times_;        // per scan
  Keyframe open_keyframe_;                  // the open keyframe (no points)
  std::vector<RadarPoint> open_points_;     // its submap so far
  std::size_t opened_ = 0;                  // keyframes opened
  double path_ = 0.0;
  bool open_ = false;
  // The back end.
  PoseGraph graph_;
  std::vector<Keyframe> keyframes_;
  PlaceDatabase places_;         // a place per closed keyframe
  VerificationTargets targets_;  // the last verified keyframes' verification maps
  std::vector<LoopCandidate> candidates_;
  std::mt19937 false_loops_;
  bool whole_solve_due_ = false;          // a local solve since the last whole one
  double last_loop_path_ = -1.0;          // m driven to the last accepted loop's query (-1: none)
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
// and RCS options, its Doppler filter) over every scan at its optimised pose,
// with the keyframes as places at their optimised poses, a revisit merged
// into the place already there (place_merge_distance). `scans` are the ones
// registered, in order.
GaussianMap BuildPlaceMap(const std::vector<RadarScan>& scans, const RadarSlam& slam);

// Writes slam.tum (each scan's optimised T_world_radar), keyframes.csv,
// loops.csv, per_scan.csv (each scan's time: total, front end, back end) and
// slam.json into `dir` (created), each file whole or not at all.
void WriteSlam(const std::string& dir, const RadarSlam& slam);

}  // namespace radargauss
