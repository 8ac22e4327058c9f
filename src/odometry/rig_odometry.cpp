// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/rig_odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Eigenvalues>

#include "radargauss/core/doppler.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/options.hpp"
#include "radargauss/core/rig_twist.hpp"

namespace radargauss {

namespace {

// Without a prediction (the first frame), the rig's twist is gated around
// the reference radar's own velocity (its sigmas, at least a floor); its
// rotation rate always around the last one.
constexpr double kReferenceGateSigmas = 3.0;
constexpr double kMinReferenceGate = 0.05;  // m/s
constexpr double kAngularGate = 0.5;        // rad/s

}  // namespace

const OptionTable<RigOdometryOptions>& RigOdometryOptionTable() {
  using O = RigOdometryOptions;
  static const OptionTable<O> table = {
      RADARGAUSS_OPTION(O, "rig_max_frame_span", max_frame_span)
          .Above(0.0)
          .Unit("s")
          .Help("a rig's frame: the longest its scans may span (it closes at the reference radar's scan)"),
      RADARGAUSS_OPTION(O, "rig_velocity", rig_velocity)
          .Help("a rig's velocity from every radar's Doppler (the rig's twist); off: the reference radar's"),
      RADARGAUSS_OPTION(O, "rig_rotation_rate", rotation_rate)
          .Choices({"yaw", "all", "off"})
          .Help("a rig's rotation rates as the rotation term's prediction: yaw; all (roll and pitch too: an elevation "
                "bias tilts them); off"),
      RADARGAUSS_OPTION(O, "rig_motion_compensation", motion_compensation)
          .Help("a rig's scans moved from their stamps to their frame's by its velocity and rotation rate"),
      RADARGAUSS_OPTION(O, "rig_calibrate", calibrate)
          .Help("estimate each radar's extrinsic and clock offset while driving, where the motion observes them"),
      RADARGAUSS_OPTION(O, "rig_calibration_window", calibration_window)
          .Above(0.0)
          .Unit("s")
          .Help("the online calibration's window: the reference's frames per estimate"),
      RADARGAUSS_OPTION(O, "rig_calibration_doppler_std", calibration_doppler_std)
          .Above(0.0)
          .Unit("m/s")
          .Help("the online calibration's Doppler residual sigma"),
      RADARGAUSS_OPTION(O, "rig_calibration_map_weight", calibration_map_weight)
          .AtLeast(0.0)
          .Help("the online calibration's points against the reference radar's map, their weight (0: the Doppler "
                "alone)"),
      RADARGAUSS_OPTION(O, "rig_calibration_prior", calibration_prior)
          .Above(0.0)
          .Unit("deg m s")
          .Help("how far the rig file's mountings may be off: rotation, translation, clock"),
      RADARGAUSS_OPTION(O, "rig_calibration_observed", calibration_observed)
          .Above(0.0)
          .Unit("deg m s")
          .Help("the std the drive must reach in a direction of a rotation, translation, clock to move it"),
  };
  return table;
}

RigFrames::RigFrames(std::vector<SE3d> body_from_radar, const OdometryOptions& options)
    : body_from_radar_(std::move(body_from_radar)),
      doppler_(options.ego_velocity),
      gate_(options),
      rig_options_(options.rig) {
  if (body_from_radar_.empty()) throw DataError("a rig's odometry needs a radar");
  CheckOptions(RigOdometryOptionTable(), rig_options_);
  if (options.elevation_bias.estimate && body_from_radar_.size() > 1) {
    throw std::invalid_argument(
        "estimate_elevation_bias: a rig's frames mix its radars' elevations (one radar's bias only)");
  }
  const SE3d reference_from_body = body_from_radar_.front().Inverse();
  for (const SE3d& mounting : body_from_radar_) reference_from_radar_.push_back(reference_from_body * mounting);
  if (rig_options_.calibrate && body_from_radar_.size() > 1) {
    online_calibration_.emplace(reference_from_radar_, rig_options_);
  }
}

std::optional<RigFrame> RigFrames::Add(std::size_t radar, const RadarScan& scan) {
  if (radar >= body_from_radar_.size()) {
    throw DataError("radar " + std::to_string(radar) + " of a rig of " + std::to_string(body_from_radar_.size()));
  }
  std::optional<RigFrame> closed;
  if (last_stamp_ && !(scan.timestamp >= *last_stamp_)) {
    throw DataError("a rig's scans must come in time order: " + std::to_string(scan.timestamp) + " s after " +
                    std::to_string(*last_stamp_) + " s");
  }
  ValidateScan(scan, "scan at " + std::to_string(scan.timestamp) + " s");
  // The frame closes after its reference scan's instant, or before a scan that would stretch it too far.
  if (!pending_.empty() && ((closing_stamp_ && scan.timestamp > *closing_stamp_) ||
                            scan.timestamp - pending_.front().timestamp > rig_options_.max_frame_span)) {
    closed = Close();
  }
  last_stamp_ = scan.timestamp;
  pending_.push_back(scan);
  pending_radars_.push_back(radar);
  if (radar == 0) closing_stamp_ = scan.timestamp;
  return closed;
}

std::optional<RigFrame> RigFrames::Finish() {
  if (pending_.empty()) return std::nullopt;
  return Close();
}

void RigFrames::Registered(double stamp, const SE3d& pose) {
  registered_.emplace_back(stamp, pose);
  if (registered_.size() > 2) registered_.erase(registered_.begin());
  if (!online_calibration_ || !reference_velocity_ || reference_velocity_->first != stamp) return;
  online_calibration_->AddReference(stamp, pose, reference_velocity_->second);
  if (online_calibration_->Update()) {
    for (std::size_t r = 1; r < reference_from_radar_.size(); ++r) {
      reference_from_radar_[r] = online_calibration_->reference_from_radar(r);
    }
  }
}

void RigFrames::ForgetMotion() {
  registered_.clear();
  if (online_calibration_) online_calibration_->Forget();
}

Eigen::Matrix<double, 6, 1> RigFrames::LastTwist() const {
  if (registered_.size() < 2) return Eigen::Matrix<double, 6, 1>::Zero();
  const auto& [before, from] = registered_.front();
  const auto& [after, to] = registered_.back();
  return (from.Inverse() * to).Log() / (after - before);
}

std::optional<VelocityGate> RigFrames::Gate(double stamp) const {
  // Around the last measured velocity, as the single-radar odometry's.
  if (!last_measured_) return std::nullopt;
  const GateOptions& o = gate_;
  const double dt = stamp - last_measured_->stamp;
  return VelocityGate{last_measured_->velocity.value, VelocityGateWidth(last_measured_->velocity.covariance, dt,
                                                                        o.gate_sigmas, o.acceleration_std, o.min_gate)};
}

RigFrames::FrameVelocity RigFrames::MeasureVelocity(const std::optional<VelocityGate>& gate) const {
  FrameVelocity out;
  out.twist = LastTwist();
  out.static_points.resize(pending_.size());
  std::vector<bool> decided(pending_.size(), false);
  // Each radar's newest scan (a twist holds at one instant; older scans would bend it).
  std::vector<std::size_t> newest;
  for (std::size_t k = pending_.size(); k-- > 0;) {
    bool seen = false;
    for (const std::size_t j : newest) seen = seen || pending_radars_[j] == pending_radars_[k];
    if (!seen) newest.push_back(k);
  }
  // The reference radar's own velocity, gated by the prediction.
  std::optional<EgoVelocityResult> reference;
  for (const std::size_t k : newest) {
    if (pending_radars_[k] != 0 || !pending_[k].has_doppler) continue;
    EgoVelocityResult own = EstimateEgoVelocity(pending_[k], doppler_, gate);
    if (own.success) {
      out.static_points[k] = own.inlier;
      decided[k] = true;
      out.measured = RadarOdometry::MeasuredVelocity{own.velocity, own.covariance, std::nullopt};
      out.twist.head<3>() = own.velocity;
      out.reference = own.velocity;
      reference = std::move(own);
    }
  }
  // A radar the online calibration has not observed yet stays out of the twist.
  newest.erase(
      std::remove_if(newest.begin(), newest.end(), [&](std::size_t k) { return !Admitted(pending_radars_[k]); }),
      newest.end());
  if (rig_options_.rig_velocity && newest.size() > 1) {
    // The rig's twist at the reference radar, gated by the prediction, and
    // its rotation rate around the last one: a car that fills one radar's
    // view cannot pull it to the car's velocity.
    std::vector<RigScan> scans;
    for (const std::size_t k : newest) scans.push_back({&pending_[k], reference_from_radar_[pending_radars_[k]]});
    RigTwistOptions options;
    options.doppler = doppler_;
    options.gate = gate;
    if (!gate && reference) {  // the first frame: around the reference radar's own velocity
      const double spread =
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(reference->covariance).eigenvalues().maxCoeff();
      options.gate = VelocityGate{reference->velocity,
                                  std::max(kMinReferenceGate, kReferenceGateSigmas * std::sqrt(std::max(spread, 0.0)))};
    }
    options.angular_gate = VelocityGate{out.twist.tail<3>(), kAngularGate};
    const RigTwist rig = EstimateRigTwist(scans, options);
    if (!gate && reference && !rig.success) {  // the rig and the reference disagree: no velocity yet
      out.measured.reset();
      out.twist = LastTwist();
    }
    // It stands when it observes the reference radar's velocity in full.
    if (rig.success && (rig.observed.topLeftCorner<3, 3>() - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
        rig.observed.topRightCorner<3, 3>().norm() < 1e-6) {
      out.measured = RadarOdometry::MeasuredVelocity{rig.velocity, rig.covariance.topLeftCorner<3, 3>(), std::nullopt};
      if (rig_options_.rotation_rate != "off" && rig.rank == 6) {
        out.measured->rate = RadarOdometry::MeasuredRate{rig.angular_velocity, rig.covariance.bottomRightCorner<3, 3>(),
                                                         rig_options_.rotation_rate == "all"};
      }
      out.by_rig = true;
      out.twist.head<3>() = rig.velocity;
      for (std::size_t n = 0; n < newest.size(); ++n) {
        out.static_points[newest[n]] = rig.inlier[n];
        decided[newest[n]] = true;
      }
    }
  }
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    if (!decided[k]) out.static_points[k] = OwnStaticPoints(k, gate, out);
  }
  return out;
}

std::vector<bool> RigFrames::OwnStaticPoints(std::size_t k, const std::optional<VelocityGate>& gate,
                                             const FrameVelocity& frame) const {
  // The radar's own Doppler filter, gated around the velocity the frame's twist gives it.
  const RadarScan& scan = pending_[k];
  std::vector<bool> keep(scan.points.size(), !scan.has_doppler);
  if (!scan.has_doppler) return keep;
  const SE3d& mounting = reference_from_radar_[pending_radars_[k]];
  std::optional<VelocityGate> own_gate = gate;
  if (gate) {
    const Eigen::Vector3d v = frame.measured ? frame.twist.head<3>() : gate->predicted;
    own_gate->predicted = RigRadarVelocity(mounting, v, frame.twist.tail<3>());
  }
  const EgoVelocityResult own = EstimateEgoVelocity(scan, doppler_, own_gate);
  if (own.success) keep = own.inlier;
  return keep;
}

RigFrame RigFrames::Close() {
  const auto start = std::chrono::steady_clock::now();
  const double stamp = closing_stamp_.value_or(pending_.back().timestamp);
  const FrameVelocity velocity = MeasureVelocity(Gate(stamp));
  // Every radar's static points in the reference frame at the frame's stamp:
  // T_ref(stamp)^-1 T_ref(t_k) = Exp(xi (t_k - stamp)) at a constant twist xi.
  RadarScan frame;
  frame.timestamp = stamp;
  frame.has_rcs = true;
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    const RadarScan& scan = pending_[k];
    SE3d to_frame = reference_from_radar_[pending_radars_[k]];
    // Its time on the body's clock, with the online calibration's change of its offset.
    const double time =
        scan.timestamp - (online_calibration_ ? online_calibration_->clock_change(pending_radars_[k]) : 0.0);
    if (rig_options_.motion_compensation && time != stamp) {
      to_frame = SE3d::Exp(velocity.twist * (time - stamp)) * to_frame;
    }
    if (online_calibration_) online_calibration_->AddScan(pending_radars_[k], scan, velocity.static_points[k]);
    if (!Admitted(pending_radars_[k])) continue;  // its points wait for its mounting, as its Doppler does
    frame.has_rcs = frame.has_rcs && scan.has_rcs;
    for (std::size_t i = 0; i < scan.points.size(); ++i) {
      if (!velocity.static_points[k][i]) continue;
      RadarPoint point = scan.points[i];
      point.position = to_frame * point.position;
      point.doppler = 0.0;
      frame.points.push_back(point);
    }
  }
  if (velocity.measured) last_measured_ = MeasuredAt{stamp, *velocity.measured};
  reference_velocity_.reset();
  if (velocity.reference) reference_velocity_.emplace(stamp, *velocity.reference);
  RigFrame out{std::move(frame), velocity.measured, velocity.by_rig, std::move(pending_radars_),
               std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count()};
  pending_radars_.clear();
  pending_.clear();
  closing_stamp_.reset();
  return out;
}

OdometryOptions ReferenceRadarOptions(OdometryOptions options, const SE3d& body_from_reference) {
  if (!options.mounting_deg.isZero(0.0)) {
    throw std::invalid_argument("mounting: a rig's mountings are in its rig file");
  }
  // R = Rz(yaw) Ry(pitch) Rx(roll), as VehicleFromRadar composes it; the
  // yaw leaves the vehicle's vertical in the radar's frame as it is.
  const Eigen::Matrix3d R = body_from_reference.rotation().Matrix();
  options.mounting_deg =
      Eigen::Vector3d(std::atan2(R(2, 1), R(2, 2)), std::asin(std::clamp(-R(2, 0), -1.0, 1.0)), 0.0) * (180.0 / M_PI);
  return options;
}

Rig OnlineCalibratedRig(const Rig& given, const RigFrames& frames) {
  Rig rig = given;
  const RigOnlineCalibration* calibration = frames.online_calibration();
  if (calibration == nullptr || calibration->radars() != rig.radars.size()) return rig;
  for (std::size_t r = 1; r < rig.radars.size(); ++r) {
    rig.radars[r].body_from_radar = frames.body_from_reference() * calibration->reference_from_radar(r);
    rig.radars[r].clock_offset += calibration->clock_change(r);
  }
  return rig;
}

std::unique_ptr<MotionModel> MakeRigMotionModel(const RadarInertialOptions& options, const SE3d& body_from_reference,
                                                const SE3d& body_from_imu, std::vector<ImuSample> imu) {
  return MakeMotionModel(options, body_from_reference.Inverse() * body_from_imu, std::move(imu));
}

RigOdometry::RigOdometry(std::vector<SE3d> body_from_radar, const OdometryOptions& options,
                         std::unique_ptr<MotionModel> motion)
    : frames_(std::move(body_from_radar), options),
      odometry_(ReferenceRadarOptions(options, frames_.body_from_reference()), std::move(motion)) {}

void RigOdometry::Register(std::size_t radar, const RadarScan& scan) {
  if (frames_.radars() == 1) {  // the single-radar odometry
    if (radar != 0) throw DataError("radar " + std::to_string(radar) + " of a rig of 1");
    odometry_.Register(scan);
    frame_radars_.push_back({radar});
    return;
  }
  if (std::optional<RigFrame> frame = frames_.Add(radar, scan)) RegisterFrame(std::move(*frame));
}

void RigOdometry::Finish() {
  if (frames_.radars() == 1) return;
  if (std::optional<RigFrame> frame = frames_.Finish()) RegisterFrame(std::move(*frame));
}

void RigOdometry::RegisterFrame(RigFrame frame) {
  const auto start = std::chrono::steady_clock::now();
  odometry_.Register(frame.scan, frame.velocity);
  frames_.Registered(frame.scan.timestamp, odometry_.pose(odometry_.scans() - 1));
  velocity_measured_ += frame.velocity.has_value();
  rig_velocity_measured_ += frame.velocity_by_rig;
  frame_radars_.push_back(std::move(frame.radars));
  frame_times_ms_.push_back(
      frame.build_ms + std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  last_frame_ = std::move(frame.scan);
}

std::size_t RegisterRigFrames(const Rig& rig, const OdometryOptions& options,
                              const std::function<RegisteredFrame(const RigFrame&)>& front_end, Rig* calibrated) {
  std::vector<SE3d> mountings;
  for (const RigRadar& radar : rig.radars) mountings.push_back(radar.body_from_radar);
  RigFrames frames(mountings, options);
  const auto give = [&](const RigFrame& frame) {
    const RegisteredFrame registered = front_end(frame);
    if (registered.jumped) frames.ForgetMotion();
    frames.Registered(frame.scan.timestamp, registered.pose);
  };
  std::size_t scans = 0;
  ForEachRigScan(rig, [&](std::size_t radar, RadarScan& scan, const std::string& source) {
    try {
      if (rig.radars.size() == 1) {
        give(RigFrame{scan, std::nullopt, false, {radar}, 0.0});
      } else if (const std::optional<RigFrame> frame = frames.Add(radar, scan)) {
        give(*frame);
      }
    } catch (const DataError& e) {
      throw DataError(source + ": " + e.what());
    }
    ++scans;
  });
  if (rig.radars.size() > 1) {
    if (const std::optional<RigFrame> frame = frames.Finish()) give(*frame);
  }
  if (calibrated != nullptr) *calibrated = OnlineCalibratedRig(rig, frames);
  return scans;
}

Trajectory BodyTrajectory(const Trajectory& reference, const SE3d& body_from_reference) {
  Trajectory body;
  for (const StampedPose& sample : reference) {
    body.Append(sample.time, body_from_reference * sample.pose * body_from_reference.Inverse());
  }
  return body;
}

Trajectory RigOdometry::trajectory() const {
  return BodyTrajectory(odometry_.trajectory(), frames_.body_from_reference());
}

}  // namespace radargauss
