// SPDX-License-Identifier: BSD-3-Clause
// SLAM's options (docs/design/slam.md, "SLAM"), shared by its parts: the
// keyframe graph, the loop search and RadarSlam, which runs them.
#pragma once

#include <cstdint>

#include "radargauss/core/options.hpp"
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
  // RadarSlam holds each keyframe's static points for the map of the place
  // (BuildPlaceMap(slam)); false: a run that writes no map. A keyframe that
  // closes within the merge distance and angle of a held keyframe (at the
  // poses estimated then) holds none unless place_map_revisits: the memory
  // is bounded by the place, not the drive.
  bool hold_map_points = true;
  bool place_map_revisits = false;
  // Whether every visit of a place is a loop candidate of later searches;
  // false: each place is answered by its newest visit, so a search's
  // candidates, and the back end's cost, stay flat over laps of a place.
  bool revisit_candidates = true;
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
// Throws std::invalid_argument naming the bad option.
void ValidateOptions(const SlamOptions& options);

}  // namespace radargauss
