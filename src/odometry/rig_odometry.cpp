// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/rig_odometry.hpp"

#include <string>
#include <utility>

#include "radargauss/core/doppler.hpp"
#include "radargauss/core/error.hpp"

namespace radargauss {

RigOdometry::RigOdometry(std::vector<SE3d> body_from_radar, const OdometryOptions& options)
    : body_from_radar_(std::move(body_from_radar)), doppler_(options.ego_velocity), odometry_(options) {
  if (body_from_radar_.empty()) throw DataError("a rig's odometry needs a radar");
}

void RigOdometry::Register(std::size_t radar, const RadarScan& scan) {
  if (radar >= body_from_radar_.size()) {
    throw DataError("radar " + std::to_string(radar) + " of a rig of " + std::to_string(body_from_radar_.size()));
  }
  if (body_from_radar_.size() == 1) {  // the single-radar odometry
    odometry_.Register(scan);
    instant_radars_.push_back({radar});
    return;
  }
  if (!pending_.empty() && scan.timestamp < pending_.front().timestamp) {
    throw DataError("a rig's scans must come in time order: " + std::to_string(scan.timestamp) + " s after " +
                    std::to_string(pending_.front().timestamp) + " s");
  }
  if (!pending_.empty() && scan.timestamp > pending_.front().timestamp) RegisterPending();
  ValidateScan(scan, "scan at " + std::to_string(scan.timestamp) + " s");
  pending_.push_back(scan);
  pending_radars_.push_back(radar);
}

void RigOdometry::Finish() {
  if (!pending_.empty()) RegisterPending();
}

void RigOdometry::RegisterPending() {
  // The odometry runs in the first radar's frame: every radar's static points
  // are moved into it, and its own Doppler velocity, when it scanned at this
  // instant, is the measured one (a velocity moved between radars would need
  // the rotation rate times the lever arm, which feeds the rate's errors back).
  const SE3d reference_from_body = body_from_radar_.front().Inverse();
  std::optional<RadarOdometry::MeasuredVelocity> measured;
  RadarScan frame;
  frame.timestamp = pending_.front().timestamp;
  frame.has_rcs = true;
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    const RadarScan& scan = pending_[k];
    const std::size_t radar = pending_radars_[k];
    std::vector<bool> keep(scan.points.size(), !scan.has_doppler);
    if (scan.has_doppler) {
      const EgoVelocityResult own = EstimateEgoVelocity(scan, doppler_);
      if (own.success) keep = own.inlier;
      if (own.success && radar == 0) measured = RadarOdometry::MeasuredVelocity{own.velocity, own.covariance};
    }
    const SE3d to_reference = reference_from_body * body_from_radar_[radar];
    frame.has_rcs = frame.has_rcs && scan.has_rcs;
    for (std::size_t i = 0; i < scan.points.size(); ++i) {
      if (!keep[i]) continue;
      RadarPoint point = scan.points[i];
      point.position = to_reference * point.position;
      point.doppler = 0.0;
      frame.points.push_back(point);
    }
  }
  velocity_measured_ += measured.has_value();
  odometry_.Register(frame, measured);
  instant_radars_.push_back(std::move(pending_radars_));
  pending_radars_.clear();
  pending_.clear();
}

Trajectory RigOdometry::trajectory() const {
  // The first radar's poses in its first frame, as the body's in the body's first frame.
  const SE3d& mounting = body_from_radar_.front();
  Trajectory body;
  for (const StampedPose& sample : odometry_.trajectory()) {
    body.Append(sample.time, mounting * sample.pose * mounting.Inverse());
  }
  return body;
}

}  // namespace radargauss
