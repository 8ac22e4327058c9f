// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/slam/relocalization.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "radargauss/core/error.hpp"
#include "radargauss/slam/radar_slam.hpp"

namespace radargauss {

namespace {

// Two T_map_odometry within `translation` m and `rotation_deg`.
bool Agree(const SE3d& a, const SE3d& b, double translation, double rotation_deg) {
  const SE3d disagreement = a.Inverse() * b;
  return disagreement.translation().norm() <= translation &&
         disagreement.rotation().Log().norm() * 180.0 / M_PI <= rotation_deg;
}

}  // namespace

const OptionTable<RelocalizationOptions>& RelocalizationOptionTable() {
  using O = RelocalizationOptions;
  static const OptionTable<O> table = [] {
    OptionTable<O> t = {
        RADARGAUSS_OPTION(O, "submap_distance", submap_distance)
            .Above(0.0)
            .Unit("m")
            .Sensor()
            .Help("a submap every this many metres driven"),
        RADARGAUSS_OPTION(O, "confirm_window", confirm_window)
            .In(1, 1000)
            .Help("a submap's places may confirm those of this many submaps before it"),
        RADARGAUSS_OPTION(O, "confirm_translation", confirm_translation)
            .Above(0.0)
            .Unit("m")
            .Help("the two poses of the odometry in the map may disagree this much"),
        RADARGAUSS_OPTION(O, "confirm_rotation", confirm_rotation_deg).Above(0.0).Unit("deg").Help("and this much"),
        RADARGAUSS_OPTION(O, "ambiguous_translation", ambiguous_translation)
            .Above(0.0)
            .Unit("m")
            .Help("agreeing places further apart alias: no fix from them"),
        RADARGAUSS_OPTION(O, "ambiguous_rotation", ambiguous_rotation_deg).Above(0.0).Unit("deg").Help("or turned"),
        RADARGAUSS_OPTION(O, "max_unmatched_scans", max_unmatched_scans)
            .AtLeast(1)
            .Help("scans in a row without a match that drop the fix"),
    };
    AppendPlaceSearchRows(t);
    return t;
  }();
  return table;
}

void ValidateOptions(const RelocalizationOptions& o) {
  CheckOptions(RelocalizationOptionTable(), o);
  ValidateOptions(o.verification);
}

Relocalizer::Relocalizer(GaussianMap map, const RelocalizationOptions& options) : options_(options) {
  ValidateOptions(options_);
  if (map.places.empty())
    throw DataError("the map has no places to relocalise against (build it with radargauss slam)");
  if (map.gaussians.empty()) throw DataError("the map has no Gaussians to match against");
  map_ = std::make_shared<const GaussianMap>(std::move(map));
  matching_ = std::make_shared<const MatchingMap>(map_);
  // Keys only: a place's full descriptor is made again when it is compared.
  places_ = std::make_unique<PlaceDatabase>(options_.place_recognition, [this](int place) {
    return places_->Describe(map_->places[std::size_t(place)].points);
  });
  for (const MapPlace& place : map_->places) places_->Add(places_->Describe(place.points));
  targets_ = std::make_unique<VerificationTargets>(options_.verification.kept_targets);
  Restart();
}

void Relocalizer::Restart() {
  odometry_ = std::make_unique<RadarOdometry>(options_.odometry);
  submap_.clear();
  path_ = submap_start_ = 0.0;
  fix_.reset();
  pending_.clear();
  unmatched_ = 0;
}

const RelocalizationStep& Relocalizer::Register(const RadarScan& scan) { return Register(scan, std::nullopt); }

const RelocalizationStep& Relocalizer::Register(const RadarScan& scan,
                                                const std::optional<RadarOdometry::MeasuredVelocity>& velocity) {
  const std::size_t index = steps_.size();
  const std::size_t local = odometry_->steps().size();  // since the last restart
  const OdometryStep& odometry = odometry_->Register(scan, velocity);
  RelocalizationStep step;
  step.stamp = odometry.stamp;
  if (fix_) {
    // Only a scan matched to the map has a pose: a prediction is not verified.
    step.fixed = step.matched = odometry.matched;
    step.pose = odometry.pose;
    step.reason = odometry.reason;
    unmatched_ = odometry.matched ? 0 : unmatched_ + 1;
    if (unmatched_ >= options_.max_unmatched_scans) {
      step.reason = "lost the map after " + std::to_string(unmatched_) + " scans without a match: searching again";
      Restart();
    }
    steps_.push_back(std::move(step));
    return steps_.back();
  }
  if (local > 0) path_ += (odometry.pose.translation() - odometry_->steps()[local - 1].pose.translation()).norm();
  if (local == 0) submap_origin_ = odometry.pose;
  const SE3d submap_from_scan = submap_origin_.Inverse() * odometry.pose;
  for (const std::size_t i : odometry_->last_static_points()) {
    RadarPoint point = scan.points[i];
    point.position = submap_from_scan * point.position;
    submap_.push_back(point);
  }
  if (path_ - submap_start_ >= options_.submap_distance) {
    Search();
    submap_.clear();
    submap_origin_ = odometry.pose;
    submap_start_ = path_;
    if (fix_) {
      if (!first_fix_) first_fix_ = index;
      ++fixes_;
      odometry_->LocalizeIn(matching_, *fix_);
      step.fixed = true;
      step.pose = *fix_ * odometry.pose;  // registered before the fix: in the odometry's frame
    }
  }
  if (!fix_) step.reason = "no verified fix yet (" + std::to_string(submaps_) + " submaps searched)";
  steps_.push_back(std::move(step));
  return steps_.back();
}

void Relocalizer::Search() {
  const int submap = submaps_++;
  const std::vector<RadarPoint> points = DownsampleSubmap(submap_, options_.place_recognition.submap_voxel);
  const std::shared_ptr<const PlaceDescription> description = places_->Describe(points);
  std::vector<int> every(places_->size());
  for (std::size_t p = 0; p < places_->size(); ++p) every[p] = int(p);
  std::vector<std::pair<SE3d, std::size_t>> found;  // T_map_odometry of each verified place, its candidate
  for (const PlaceMatch& match : places_->Rank(*description, every)) {
    PlaceCandidate candidate;
    candidate.submap = submap;
    candidate.place = match.candidate;
    candidate.distance = match.distance;
    candidate.yaw = match.yaws.front();
    if (!match.close) {
      char reason[64];
      std::snprintf(reason, sizeof(reason), "descriptor distance %.3f", match.distance);
      candidate.check.reason = reason;
    } else {
      candidate.verified = true;
      const std::shared_ptr<const VerificationTarget> target =
          targets_->Get(match.candidate, map_->places[std::size_t(match.candidate)].points, options_.verification);
      for (const double yaw : match.yaws) {
        LoopCheck check = VerifyLoop(points, *target, yaw, std::nullopt, options_.verification);
        if (check.accepted || yaw == match.yaws.front() || check.associated > candidate.check.associated) {
          candidate.check = std::move(check);
          candidate.yaw = yaw;
        }
        if (candidate.check.accepted) break;
      }
      // The place's pose times the match gives the submap's origin in the map.
      if (candidate.check.accepted) {
        found.emplace_back(map_->places[match.candidate].pose * candidate.check.relative * submap_origin_.Inverse(),
                           candidates_.size());
      }
    }
    candidates_.push_back(std::move(candidate));
  }
  Confirm(found);
}

// A fix needs a verified place of this submap to agree with one of the
// recent submaps' (places alias, a true place recurs); when the agreeing
// places lie far apart, or a better-ranked verified place lies apart from
// them, the straight aliases along itself and the next submap decides.
void Relocalizer::Confirm(const std::vector<std::pair<SE3d, std::size_t>>& found) {
  std::vector<std::pair<SE3d, std::size_t>> agreeing;
  for (const auto& hypothesis : found) {
    const auto agrees = [&](const SE3d& before) {
      return Agree(before, hypothesis.first, options_.confirm_translation, options_.confirm_rotation_deg);
    };
    if (std::any_of(pending_.begin(), pending_.end(),
                    [&](const std::vector<SE3d>& s) { return std::any_of(s.begin(), s.end(), agrees); })) {
      agreeing.push_back(hypothesis);
    }
  }
  // Unique: no agreeing place, and no place the descriptor ranks better
  // than the best agreeing one, lies apart from that one.
  if (!agreeing.empty()) {
    const auto& best = agreeing.front();
    const auto apart = [&](const auto& h) {
      return !Agree(best.first, h.first, options_.ambiguous_translation, options_.ambiguous_rotation_deg);
    };
    const auto ranked_better_and_apart = [&](const auto& h) { return h.second < best.second && apart(h); };
    if (std::none_of(agreeing.begin(), agreeing.end(), apart) &&
        std::none_of(found.begin(), found.end(), ranked_better_and_apart)) {
      fix_ = best.first;
      candidates_[best.second].fixed = true;
    } else {
      for (const auto& h : agreeing) candidates_[h.second].check.reason = "ambiguous: agreeing places disagree";
    }
  }
  pending_.emplace_back();
  for (const auto& hypothesis : found) pending_.back().push_back(hypothesis.first);
  if (int(pending_.size()) > options_.confirm_window) pending_.pop_front();
}

}  // namespace radargauss
