// SPDX-License-Identifier: BSD-3-Clause
// Relocalisation in a SLAM map without an initial pose (docs/design/slam.md,
// "Relocalisation"): the run's own odometry accumulates submaps of
// submap_distance metres; each is described and its nearest places of the
// map verified (slam/loop_verification.hpp, no graph prior). Two submaps
// (within confirm_window of each other) whose verified places put the
// odometry at the same pose in the map make the fix (one alone is not
// trusted: places alias); every verified place of both is considered, and
// agreeing pairs far apart from each other (a straight that aliases along
// itself) wait for the next.
// From that fix on, the odometry matches every scan against the fixed map
// with its motion model and priors (RadarOdometry::LocalizeIn). Before a fix
// no pose is reported.
//
//   Relocalizer relocalizer(ReadMap(path), options);
//   for (const RadarScan& scan : sequence.scans) relocalizer.Register(scan);
#pragma once

#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/matching_map.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/slam/loop_verification.hpp"
#include "radargauss/slam/place_recognition.hpp"
#include "radargauss/solvers/factory.hpp"

namespace radargauss {

struct RelocalizationOptions {
  OdometryOptions odometry;       // the front end: submaps before the fix, tracking after
  double submap_distance = 10.0;  // m driven per submap
  PlaceRecognitionOptions place_recognition;
  LoopVerificationOptions verification;
  // A submap's places may confirm those of the confirm_window submaps before
  // it; the two poses of the odometry in the map may disagree this much.
  int confirm_window = 3;
  double confirm_translation = 1.0;  // m
  double confirm_rotation_deg = 2.0;
  // Agreeing places further apart than this alias (the laps of a map
  // disagree by less): no fix from them.
  double ambiguous_translation = 5.0;  // m
  double ambiguous_rotation_deg = 5.0;
  // After this many scans in a row without a match to the map the fix is
  // dropped and the search starts again with a fresh odometry.
  int max_unmatched_scans = 10;
};

// Its options (options.hpp): its own, the odometry's, place recognition's
// and the verification's (verify_*); ValidateOptions throws
// std::invalid_argument naming the bad one.
const OptionTable<RelocalizationOptions>& RelocalizationOptionTable();
void ValidateOptions(const RelocalizationOptions& options);

struct RelocalizationStep {
  double stamp = 0.0;
  bool fixed = false;    // a pose is reported: the fix's scan, or a scan matched to the map after it
  SE3d pose;             // T_map_radar when fixed
  bool matched = false;  // the pose is this scan's match against the map
  std::string reason;    // why there is no pose or no match
};

// A submap compared with a place of the map.
struct PlaceCandidate {
  int submap = 0, place = 0;
  double distance = 1.0;  // the descriptor's
  double yaw = 0.0;       // rad
  bool verified = false;
  LoopCheck check;     // check.accepted: verified
  bool fixed = false;  // it confirmed the submap before's place: the fix
};

class Relocalizer {
 public:
  // Throws DataError when the map has no places (it was not built by SLAM)
  // and std::invalid_argument for bad options.
  Relocalizer(GaussianMap map, const RelocalizationOptions& options = {});

  const RelocalizationStep& Register(const RadarScan& scan);
  // The same for a scan without Doppler whose velocity was measured apart
  // (a rig's frame, odometry/rig_odometry.hpp).
  const RelocalizationStep& Register(const RadarScan& scan,
                                     const std::optional<RadarOdometry::MeasuredVelocity>& velocity);

  bool fixed() const { return fix_.has_value(); }
  // The index of the scan at which the first fix was made.
  std::optional<std::size_t> first_fix() const { return first_fix_; }
  std::size_t fixes() const { return fixes_; }  // more than one: tracking was lost and found again
  const std::vector<RelocalizationStep>& steps() const { return steps_; }
  const std::vector<PlaceCandidate>& candidates() const { return candidates_; }
  const RadarOdometry& odometry() const { return *odometry_; }

 private:
  // Describes the closed submap and verifies its candidates; sets fix_ on success.
  void Search();
  // Makes the fix from this submap's verified T_map_odometry (and their
  // candidates' indices) and those of the submaps before.
  void Confirm(const std::vector<std::pair<SE3d, std::size_t>>& found);
  // A fresh odometry and submap from the next scan on.
  void Restart();

  RelocalizationOptions options_;
  std::shared_ptr<const GaussianMap> map_;
  std::shared_ptr<const MatchingMap> matching_;
  std::unique_ptr<PlaceDatabase> places_;         // the map's places by key, described again when compared
  std::unique_ptr<VerificationTargets> targets_;  // the last verified places' verification maps
  std::unique_ptr<RadarOdometry> odometry_;
  std::vector<RelocalizationStep> steps_;
  std::vector<PlaceCandidate> candidates_;
  std::vector<RadarPoint> submap_;  // the open submap, in the frame of its first scan
  SE3d submap_origin_;              // the odometry's pose of that scan
  double submap_start_ = 0.0, path_ = 0.0;
  int submaps_ = 0;
  std::optional<SE3d> fix_;                // T_map_odometry at the fix
  std::deque<std::vector<SE3d>> pending_;  // the last submaps' verified T_map_odometry, awaiting confirmation
  std::optional<std::size_t> first_fix_;
  std::size_t fixes_ = 0;  // how many fixes were made
  int unmatched_ = 0;      // scans in a row without a match since the fix
};

}  // namespace radargauss
