// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/rig_calibration.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <utility>

#include <Eigen/Eigenvalues>

#include "radargauss/core/doppler.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/rig_twist.hpp"
#include "radargauss/lie/manifold.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/odometry/rig_odometry.hpp"
#include "radargauss/residuals/rig_doppler_residual.hpp"
#include "rig_reference_motion.hpp"

namespace radargauss {

const OptionTable<RigCalibrationOptions>& RigCalibrationOptionTable() {
  using O = RigCalibrationOptions;
  static const OptionTable<O> table = [] {
    OptionTable<O> t = {
        RADARGAUSS_OPTION(O, "estimate_rotation", estimate_rotation).Sensor().Help("estimate each radar's rotation"),
        RADARGAUSS_OPTION(O, "estimate_translation", estimate_translation)
            .Sensor()
            .Help("estimate each radar's translation"),
        RADARGAUSS_OPTION(O, "estimate_clock_offset", estimate_clock_offset)
            .Sensor()
            .Help("estimate each radar's clock offset"),
        RADARGAUSS_OPTION(O, "doppler_std", doppler_std).Above(0.0).Unit("m/s").Help("a Doppler residual's sigma"),
        RADARGAUSS_OPTION(O, "map_weight", map_weight)
            .AtLeast(0.0)
            .Help("weight of the points against the reference's map (0: the Doppler alone)"),
        RADARGAUSS_OPTION(O, "points_per_scan", points_per_scan).In(1, 10000).Help("static points used per scan"),
        RADARGAUSS_OPTION(O, "rounds", rounds).In(1, 100).Help("re-associations and re-readings of the motion"),
        RADARGAUSS_OPTION(O, "loss_scale", loss_scale).Above(0.0).Help("Huber loss scale (sigmas)"),
        RADARGAUSS_OPTION(O, "map_max_age", map_max_age)
            .Above(0.0)
            .Unit("s")
            .Help("a point meets only the Gaussians the reference saw within this time of its scan"),
        RADARGAUSS_OPTION(O, "association_gate", association_gate)
            .Above(0.0)
            .Help("Mahalanobis distance of a point to its Gaussian"),
        RADARGAUSS_OPTION(O, "min_relative_eigenvalue", min_relative_eigenvalue)
            .In(0.0, 1.0)
            .Help("information directions below this share of the largest are unobserved"),
    };
    return t;
  }();
  return table;
}

void ValidateOptions(const RigCalibrationOptions& options) {
  CheckOptions(RigCalibrationOptionTable(), options);
  ValidateOptions(options.reference);
  ValidateOptions(options.map);
}

namespace {

using rig_calibration::BuildReferenceMap;
using rig_calibration::GyroRatesOf;
using rig_calibration::ReferenceMap;
using rig_calibration::ReferenceTrack;

// A radar's static points used: the Doppler filter's inliers, gated around
// the velocity the reference's motion gives the radar at its given
// extrinsic, at most `count` spread over the scan.
std::vector<std::size_t> UsedPoints(const RadarScan& scan, const ReferenceMotion& motion, const SE3d& extrinsic,
                                    const RigCalibrationOptions& options) {
  std::vector<std::size_t> used;
  if (!scan.has_doppler) return used;
  const Eigen::Vector3d expected = RigRadarVelocity(extrinsic, motion.velocity, motion.angular_velocity);
  const VelocityGate gate{expected, std::max(options.reference.min_gate, 0.1 * expected.norm())};
  const EgoVelocityResult ego = EstimateEgoVelocity(scan, options.reference.ego_velocity, gate);
  if (!ego.success) return used;
  std::vector<std::size_t> inliers;
  for (std::size_t i = 0; i < ego.inlier.size(); ++i) {
    if (ego.inlier[i]) inliers.push_back(i);
  }
  const std::size_t stride =
      std::max<std::size_t>(1, (inliers.size() + options.points_per_scan - 1) / options.points_per_scan);
  for (std::size_t k = 0; k < inliers.size(); k += stride) used.push_back(inliers[k]);
  return used;
}

struct RadarBlocks {
  Eigen::Vector4d rotation;  // x y z w of R_ref_radar
  Eigen::Vector3d translation;
  double clock_change = 0.0;  // s: the offset's change in this round
};

// The standard deviations of the 7 tangent directions (rotation, translation,
// clock) at the problem's solution, clustered by scan: C = H^+ B H^+ with
// H = J^T J and B the sum over scans of g g^T, g = J_s^T r_s. A scan's
// residuals share its reference motion's errors, so they are not counted as
// independent. Infinite along the directions H leaves unobserved.
Eigen::Matrix<double, 7, 1> TangentStd(ceres::Problem& problem, RadarBlocks& blocks,
                                       const std::vector<ceres::ResidualBlockId>& residuals,
                                       const std::vector<std::size_t>& scan_of, double min_relative) {
  using Matrix7d = Eigen::Matrix<double, 7, 7>;
  using Vector7d = Eigen::Matrix<double, 7, 1>;
  Vector7d std = Vector7d::Constant(std::numeric_limits<double>::infinity());
  const std::optional<rig_calibration::ClusteredMoments> moments = rig_calibration::ClusteredByScan(
      problem, {blocks.rotation.data(), blocks.translation.data(), &blocks.clock_change}, residuals, scan_of);
  if (!moments) return std;
  const Matrix7d& information = moments->information;
  const Matrix7d& spread = moments->spread;
  const Eigen::SelfAdjointEigenSolver<Matrix7d> eigen(information);
  const double largest = eigen.eigenvalues().maxCoeff();
  Matrix7d inverse = Matrix7d::Zero();
  Vector7d open = Vector7d::Zero();  // each coordinate's weight in the unobserved directions
  for (int k = 0; k < 7; ++k) {
    const Vector7d direction = eigen.eigenvectors().col(k);
    if (largest > 0.0 && eigen.eigenvalues()(k) > min_relative * largest) {
      inverse += direction * direction.transpose() / eigen.eigenvalues()(k);
    } else {
      open += direction.cwiseAbs2();
    }
  }
  const Matrix7d covariance = inverse * spread * inverse;
  for (int k = 0; k < 7; ++k) {
    if (open(k) < 1e-6) std(k) = std::sqrt(covariance(k, k));
  }
  return std;
}

// A round's residuals: their ids and scans (for the clustered deviations)
// and how many of each kind.
struct RoundResiduals {
  std::vector<ceres::ResidualBlockId> ids;
  std::vector<std::size_t> scan_of;
  std::size_t doppler = 0, map = 0;
};

// Scan s's used points into `problem`: each one's Doppler and, with the map,
// its position against the Gaussian it meets.
void AddScanResiduals(const RadarScan& scan, std::size_t s, const std::vector<std::size_t>& used, double t,
                      const ReferenceTrack& track, const ReferenceMap& map, bool with_map,
                      const RigCalibrationOptions& options, RadarBlocks& blocks, ceres::Problem& problem,
                      RoundResiduals& out) {
  const SE3d extrinsic(SO3d::FromXyzw(blocks.rotation.data()), blocks.translation);
  const ReferenceMotion motion = track.Motion(t);
  const SE3d world_from_reference = track.Pose(t);
  const SE3d reference_from_world = world_from_reference.Inverse();
  for (const std::size_t i : used) {
    const RadarPoint& point = scan.points[i];
    out.ids.push_back(problem.AddResidualBlock(
        new RigDopplerCostFunction(point.position, point.doppler, motion, 1.0 / options.doppler_std),
        new ceres::HuberLoss(options.loss_scale), blocks.rotation.data(), blocks.translation.data(),
        &blocks.clock_change));
    out.scan_of.push_back(s);
    ++out.doppler;
    if (options.map_weight <= 0.0 || !with_map) continue;
    ceres::CostFunction* cost = map.PointCost(point.position, t, extrinsic, world_from_reference, reference_from_world,
                                              motion, options.association_gate, options.map_max_age);
    if (cost == nullptr) continue;
    out.ids.push_back(problem.AddResidualBlock(
        cost,
        new ceres::ScaledLoss(new ceres::HuberLoss(options.loss_scale), options.map_weight, ceres::TAKE_OWNERSHIP),
        blocks.rotation.data(), blocks.translation.data(), &blocks.clock_change));
    out.scan_of.push_back(s);
    ++out.map;
  }
}

// One radar's extrinsic and clock offset, refined in rounds.
RadarCalibration CalibrateRadar(const RigRadar& radar, const SE3d& reference_from_radar,
                                const std::vector<RadarScan>& scans, const ReferenceTrack& track,
                                const ReferenceMap& map, const RigCalibrationOptions& options) {
  RadarCalibration out;
  out.name = radar.name;
  RadarBlocks blocks{reference_from_radar.rotation().quaternion().coeffs(), reference_from_radar.translation()};
  double clock_offset = radar.clock_offset;
  std::vector<std::vector<std::size_t>> used(scans.size());
  for (std::size_t s = 0; s < scans.size(); ++s) {
    const double t = scans[s].timestamp - clock_offset;
    if (!track.Covers(t)) continue;
    used[s] = UsedPoints(scans[s], track.Motion(t), reference_from_radar, options);
    ++out.scans;
  }
  if (out.scans == 0) throw DataError("radar '" + radar.name + "': no scan within the reference radar's drive");
  SO3Manifold so3;
  Eigen::Matrix<double, 7, 1> std = Eigen::Matrix<double, 7, 1>::Zero();
  for (int round = 0; round < options.rounds; ++round) {
    // Coarse to fine: the rotation from the Doppler first (its strongest
    // signal), then the translation with the map, then the clock.
    const bool with_map = round >= 1 || options.rounds == 1;
    const bool with_clock = round >= 2 || options.rounds <= 2;
    ceres::Problem::Options problem_options;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    problem.AddParameterBlock(blocks.rotation.data(), 4, &so3);
    problem.AddParameterBlock(blocks.translation.data(), 3);
    problem.AddParameterBlock(&blocks.clock_change, 1);
    RoundResiduals residuals;
    for (std::size_t s = 0; s < scans.size(); ++s) {
      const double t = scans[s].timestamp - clock_offset;
      if (used[s].empty() || !track.Covers(t)) continue;
      AddScanResiduals(scans[s], s, used[s], t, track, map, with_map, options, blocks, problem, residuals);
    }
    out.doppler_points = residuals.doppler;
    out.map_points = residuals.map;
    if (!options.estimate_rotation) problem.SetParameterBlockConstant(blocks.rotation.data());
    if (!options.estimate_translation || !with_map) problem.SetParameterBlockConstant(blocks.translation.data());
    if (!options.estimate_clock_offset || !with_clock) problem.SetParameterBlockConstant(&blocks.clock_change);
    rig_calibration::SolveDense(problem, 50);
    std = TangentStd(problem, blocks, residuals.ids, residuals.scan_of, options.min_relative_eigenvalue);
    clock_offset += blocks.clock_change;
    blocks.clock_change = 0.0;
  }
  out.body_from_radar = SE3d(SO3d::FromXyzw(blocks.rotation.data()), blocks.translation);  // T_ref_radar for now
  out.clock_offset = clock_offset;
  out.rotation_std = options.estimate_rotation ? Eigen::Vector3d(std.head<3>()) : Eigen::Vector3d::Zero();
  out.translation_std = options.estimate_translation ? Eigen::Vector3d(std.segment<3>(3)) : Eigen::Vector3d::Zero();
  out.clock_offset_std = options.estimate_clock_offset ? std(6) : 0.0;
  return out;
}

}  // namespace

RigCalibration CalibrateRig(const Rig& rig, const std::vector<std::vector<RadarScan>>& scans,
                            const RigCalibrationOptions& options, const std::optional<RigImu>& imu) {
  ValidateOptions(options);
  if (scans.size() != rig.radars.size()) {
    throw DataError("a rig of " + std::to_string(rig.radars.size()) + " radars with the scans of " +
                    std::to_string(scans.size()));
  }
  if (scans.front().size() < 3) throw DataError("radar '" + rig.radars.front().name + "': fewer than 3 scans");
  // The reference radar's odometry on the body's clock, and its map.
  std::vector<RadarScan> reference_scans = scans.front();
  for (RadarScan& scan : reference_scans) scan.timestamp -= rig.radars.front().clock_offset;
  const SE3d& body_from_reference = rig.radars.front().body_from_radar;
  // With the IMU, the reference's odometry runs with its window (in the
  // reference radar's frame, as a rig's odometry does).
  RadarOdometry odometry(
      options.reference,
      imu ? MakeRigMotionModel(imu->inertial, body_from_reference, imu->body_from_imu, imu->samples) : nullptr);
  for (const RadarScan& scan : reference_scans) odometry.Register(scan);
  ReferenceTrack track(odometry.steps());
  std::vector<GyroSample> gyro;
  if (const InertialMotion* inertial = imu ? InertialMotionOf(odometry) : nullptr) {
    gyro = GyroRatesOf(*inertial, imu->samples);
  }
  std::vector<SE3d> poses;
  for (const OdometryStep& step : odometry.steps()) poses.push_back(step.pose);
  const ReferenceMap map = BuildReferenceMap(reference_scans, poses, options.map);

  RigCalibration result;
  result.rig = rig;
  result.reference = odometry.trajectory();
  result.gyro = !gyro.empty();
  track.UseGyro(std::move(gyro));
  RadarCalibration reference;
  reference.name = rig.radars.front().name;
  reference.body_from_radar = body_from_reference;
  reference.clock_offset = rig.radars.front().clock_offset;
  reference.scans = scans.front().size();
  result.radars.push_back(reference);
  for (std::size_t r = 1; r < rig.radars.size(); ++r) {
    const RigRadar& radar = rig.radars[r];
    RadarCalibration calibration =
        CalibrateRadar(radar, body_from_reference.Inverse() * radar.body_from_radar, scans[r], track, map, options);
    calibration.body_from_radar = body_from_reference * calibration.body_from_radar;
    result.rig.radars[r].body_from_radar = calibration.body_from_radar;
    result.rig.radars[r].clock_offset = calibration.clock_offset;
    result.radars.push_back(std::move(calibration));
  }
  return result;
}

}  // namespace radargauss
