// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/rig_online_calibration.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "radargauss/core/error.hpp"
#include "radargauss/core/options.hpp"
#include "radargauss/lie/manifold.hpp"
#include "radargauss/residuals/priors.hpp"
#include "radargauss/residuals/rig_doppler_residual.hpp"
#include "radargauss/solvers/calibration_gate.hpp"
#include "rig_reference_motion.hpp"

namespace radargauss {

namespace {

constexpr std::size_t kPointsPerScan = 40;  // a scan's static points kept, spread over it
constexpr double kLossScale = 2.0;          // Huber, in sigmas (and Mahalanobis distance)
constexpr double kAssociationGate = 3.0;    // Mahalanobis distance of a point to its Gaussian
constexpr int kRounds = 4;                  // per window: the rotation, the translation, the clock twice
constexpr double kImprobableMove = 24.32;   // chi-square, 7 degrees of freedom, 99.9 %
constexpr double kMapMaxAge = 2.0;          // s: a point meets the Gaussians the reference saw within this
constexpr double kDegree = M_PI / 180.0;

// The estimate so far as a prior on the window's solve: with e = [Log(R_a^T R);
// t - t_a; c + d], r = U e for the prior's information U^T U (7 residuals on
// the rotation, the translation and the clock's change d, beyond the change
// c already read into the motion).
class MountingPrior final : public ceres::SizedCostFunction<7, 4, 3, 1> {
 public:
  MountingPrior(const SE3d& anchor, const Eigen::Matrix<double, 7, 7>& sqrt_information, double clock_moved)
      : anchor_(anchor), U_(sqrt_information), clock_moved_(clock_moved) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const SO3d rotation = SO3d::FromXyzw(parameters[0]);
    RotationPrior rotation_error;
    rotation_error.predicted = anchor_.rotation();
    Eigen::Matrix<double, 7, 1> e;
    e << rotation_error.Residual(rotation), Eigen::Map<const Eigen::Vector3d>(parameters[1]) - anchor_.translation(),
        clock_moved_ + parameters[2][0];
    Eigen::Map<Eigen::Matrix<double, 7, 1>> r(residuals);
    r = U_ * e;
    if (jacobians == nullptr) return true;
    if (jacobians[0] != nullptr) {  // dr/dq = U_rot Jr^-1 4 P^T, as RotationCostFunction's
      Eigen::Matrix<double, 4, 3, Eigen::RowMajor> P;
      SO3Manifold().PlusJacobian(parameters[0], P.data());
      Eigen::Map<Eigen::Matrix<double, 7, 4, Eigen::RowMajor>> J(jacobians[0]);
      J = 4.0 * U_.leftCols<3>() * rotation_error.Jacobian(rotation) * P.transpose();
    }
    if (jacobians[1] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 7, 3, Eigen::RowMajor>> J(jacobians[1]);
      J = U_.middleCols<3>(3);
    }
    if (jacobians[2] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 7, 1>> J(jacobians[2]);
      J = U_.col(6);
    }
    return true;
  }

 private:
  SE3d anchor_;
  Eigen::Matrix<double, 7, 7> U_;
  double clock_moved_;  // s: the clock's change already read into the motion
};

// What a window's data tell of the mounting, clustered by scan: the inverse
// of the sandwich covariance H^-1 B H^-1, that is H B^-1 H (H when the
// residuals are independent and of their sigmas; less when a scan's share the
// reference motion's errors). Directions B leaves empty are floored.
Eigen::Matrix<double, 7, 7> WindowInformation(ceres::Problem& problem, const std::vector<double*>& blocks,
                                              const std::vector<ceres::ResidualBlockId>& ids,
                                              const std::vector<std::size_t>& scan_of) {
  using Matrix7d = Eigen::Matrix<double, 7, 7>;
  const std::optional<rig_calibration::ClusteredMoments> moments =
      rig_calibration::ClusteredByScan(problem, blocks, ids, scan_of);
  if (!moments) return Matrix7d::Zero();
  const Eigen::SelfAdjointEigenSolver<Matrix7d> spread(moments->spread);
  const double floor = std::max(1e-12, 1e-9 * spread.eigenvalues().maxCoeff());
  const Matrix7d spread_inverse = spread.eigenvectors() *
                                  spread.eigenvalues().cwiseMax(floor).cwiseInverse().asDiagonal() *
                                  spread.eigenvectors().transpose();
  const Matrix7d information = moments->information * spread_inverse * moments->information;
  return 0.5 * (information + information.transpose());
}

}  // namespace

RigOnlineCalibration::RigOnlineCalibration(std::vector<SE3d> reference_from_radar, const RigOdometryOptions& options)
    : options_(options) {
  CheckOptions(RigOdometryOptionTable(), options_);
  Vector7d prior_std;
  prior_std << Eigen::Vector3d::Constant(options.calibration_prior(0) * kDegree),
      Eigen::Vector3d::Constant(options.calibration_prior(1)), options.calibration_prior(2);
  for (const SE3d& mounting : reference_from_radar) {
    Estimate estimate;
    estimate.given = estimate.free = estimate.applied = mounting;
    estimate.prior_information = prior_std.cwiseAbs2().cwiseInverse().asDiagonal();
    estimate.information = estimate.prior_information;
    estimate.covariance = estimate.prior_information.inverse();
    estimates_.push_back(std::move(estimate));
  }
}

void RigOnlineCalibration::AddReference(double stamp, const SE3d& world_from_reference,
                                        const Eigen::Vector3d& velocity) {
  OdometryStep step;
  step.stamp = stamp;
  step.pose = world_from_reference;
  step.velocity = velocity;
  if (!reference_.empty() && !(stamp > reference_.back().stamp)) return;  // one motion per instant
  reference_.push_back(std::move(step));
  if (reference_scan_ && reference_scan_->timestamp == stamp) {  // its scan joins the map
    map_scans_.push_back(std::move(*reference_scan_));
    map_poses_.push_back(world_from_reference);
  }
  reference_scan_.reset();
}

void RigOnlineCalibration::AddScan(std::size_t radar, const RadarScan& scan, const std::vector<bool>& static_points) {
  if (radar == 0 && options_.calibration_map_weight > 0.0) {  // the reference's static points, for the map
    RadarScan kept;
    kept.timestamp = scan.timestamp;
    for (std::size_t i = 0; i < static_points.size() && i < scan.points.size(); ++i) {
      if (static_points[i]) kept.points.push_back(scan.points[i]);
    }
    reference_scan_ = std::move(kept);
    return;
  }
  if (radar == 0 || radar >= estimates_.size() || !scan.has_doppler) return;
  std::vector<std::size_t> inliers;
  for (std::size_t i = 0; i < static_points.size() && i < scan.points.size(); ++i) {
    if (static_points[i]) inliers.push_back(i);
  }
  if (inliers.empty()) return;
  WindowScan kept{radar, scan.timestamp, {}, {}};
  const std::size_t stride = std::max<std::size_t>(1, (inliers.size() + kPointsPerScan - 1) / kPointsPerScan);
  for (std::size_t k = 0; k < inliers.size(); k += stride) {
    kept.positions.push_back(scan.points[inliers[k]].position);
    kept.dopplers.push_back(scan.points[inliers[k]].doppler);
  }
  scans_.push_back(std::move(kept));
}

void RigOnlineCalibration::Forget() {
  reference_.clear();
  scans_.clear();
  map_scans_.clear();
  map_poses_.clear();
  reference_scan_.reset();
}

bool RigOnlineCalibration::Update() {
  if (reference_.size() < 4 || reference_.back().stamp - reference_.front().stamp < options_.calibration_window) {
    return false;
  }
  // The reference's map of the window (and of the map_max_age before it).
  std::optional<rig_calibration::ReferenceMap> map;
  if (options_.calibration_map_weight > 0.0 && !map_scans_.empty()) {
    try {
      map = rig_calibration::BuildReferenceMap(map_scans_, map_poses_, MapOptions{});
    } catch (const DataError&) {  // no static point: the Doppler alone
    }
  }
  bool moved = false;
  for (std::size_t r = 1; r < estimates_.size(); ++r) moved = Solve(r, reference_, map ? &*map : nullptr) || moved;
  ++windows_;
  // The window is left behind: its scans up to its last covered instant, its
  // frames but the last two (the next window's motion starts between them).
  const std::size_t n = reference_.size();
  const double covered = 0.5 * (reference_[n - 2].stamp + reference_[n - 1].stamp);
  scans_.erase(std::remove_if(scans_.begin(), scans_.end(),
                              [&](const WindowScan& s) { return s.stamp - estimates_[s.radar].free_clock < covered; }),
               scans_.end());
  reference_.erase(reference_.begin(), reference_.end() - 2);
  std::size_t old = 0;
  while (old < map_scans_.size() && map_scans_[old].timestamp < covered - kMapMaxAge) ++old;
  map_scans_.erase(map_scans_.begin(), map_scans_.begin() + std::ptrdiff_t(old));
  map_poses_.erase(map_poses_.begin(), map_poses_.begin() + std::ptrdiff_t(old));
  return moved;
}

bool RigOnlineCalibration::Solve(std::size_t radar, const std::vector<OdometryStep>& steps,
                                 const rig_calibration::ReferenceMap* map) {
  Estimate& estimate = estimates_[radar];
  const rig_calibration::ReferenceTrack track(steps);
  const Matrix7d sqrt_information = estimate.information.llt().matrixU();
  Eigen::Vector4d rotation = estimate.free.rotation().quaternion().coeffs();
  Eigen::Vector3d translation = estimate.free.translation();
  double moved_clock = 0.0;  // the clock's change in this window
  Matrix7d data = Matrix7d::Zero();
  SO3Manifold so3;
  for (int round = 0; round < kRounds; ++round) {
    // Coarse to fine, as offline: the rotation from the Doppler, then the
    // translation with the map, then the clock; each round re-associates the
    // points and re-reads the motion at the clock so far.
    const bool last = round + 1 == kRounds;
    const bool with_map = map != nullptr && round >= 1;
    double clock = 0.0;
    ceres::Problem::Options problem_options;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    problem.AddParameterBlock(rotation.data(), 4, &so3);
    problem.AddParameterBlock(translation.data(), 3);
    problem.AddParameterBlock(&clock, 1);
    const SE3d extrinsic(SO3d::FromXyzw(rotation.data()), translation);
    std::vector<ceres::ResidualBlockId> ids;  // the data's residuals and their scans
    std::vector<std::size_t> scan_of;
    for (std::size_t s = 0; s < scans_.size(); ++s) {
      const WindowScan& scan = scans_[s];
      const double t = scan.stamp - estimate.free_clock - moved_clock;
      if (scan.radar != radar || !track.Covers(t)) continue;
      const ReferenceMotion motion = track.Motion(t);
      const SE3d world_from_reference = track.Pose(t);
      const SE3d reference_from_world = world_from_reference.Inverse();
      for (std::size_t i = 0; i < scan.positions.size(); ++i) {
        ids.push_back(problem.AddResidualBlock(new RigDopplerCostFunction(scan.positions[i], scan.dopplers[i], motion,
                                                                          1.0 / options_.calibration_doppler_std),
                                               new ceres::HuberLoss(kLossScale), rotation.data(), translation.data(),
                                               &clock));
        scan_of.push_back(s);
        // Its position against the reference's map, as the offline calibration's.
        ceres::CostFunction* cost = with_map
                                        ? map->PointCost(scan.positions[i], t, extrinsic, world_from_reference,
                                                         reference_from_world, motion, kAssociationGate, kMapMaxAge)
                                        : nullptr;
        if (cost == nullptr) continue;
        ids.push_back(
            problem.AddResidualBlock(cost,
                                     new ceres::ScaledLoss(new ceres::HuberLoss(kLossScale),
                                                           options_.calibration_map_weight, ceres::TAKE_OWNERSHIP),
                                     rotation.data(), translation.data(), &clock));
        scan_of.push_back(s);
      }
    }
    if (ids.size() < 7) return false;
    problem.AddResidualBlock(new MountingPrior(estimate.free, sqrt_information, moved_clock), nullptr, rotation.data(),
                             translation.data(), &clock);
    if (round < 1) problem.SetParameterBlockConstant(translation.data());
    if (round < 2) problem.SetParameterBlockConstant(&clock);
    rig_calibration::SolveDense(problem, 20);
    if (last) data = WindowInformation(problem, {rotation.data(), translation.data(), &clock}, ids, scan_of);
    moved_clock += clock;
  }
  // A window whose estimate the rig file holds improbable (beyond the 99.9 %
  // bound of chi-square with 7 degrees of freedom under the prior) is set
  // aside: a reference motion gone wrong, or another minimum.
  const SE3d solved(SO3d::FromXyzw(rotation.data()), translation);
  Vector7d from_given;
  from_given << (estimate.given.rotation().Inverse() * solved.rotation()).Log(),
      solved.translation() - estimate.given.translation(), estimate.free_clock + moved_clock;
  if (!(from_given.dot(estimate.prior_information * from_given) <= kImprobableMove)) {
    ++estimate.windows_set_aside;
    return false;
  }
  estimate.free = solved;
  estimate.free_clock += moved_clock;
  estimate.information += data;
  return Apply(estimate);
}

bool RigOnlineCalibration::Apply(Estimate& estimate) const {
  // The gate over the drive so far: each block's directions whose data (the
  // prior taken out) state a std of at most the observed one move from the
  // given mounting to the free estimate; the others stay as given.
  Vector7d change;
  change << (estimate.given.rotation().Inverse() * estimate.free.rotation()).Log(),
      estimate.free.translation() - estimate.given.translation(), estimate.free_clock;
  const double observed_std[3] = {options_.calibration_observed(0) * kDegree, options_.calibration_observed(1),
                                  options_.calibration_observed(2)};
  const int offsets[3] = {0, 3, 6}, sizes[3] = {3, 3, 1};
  // The applied estimate's covariance: the free one's along the observed
  // directions, the prior's along the others (the given mounting's).
  Matrix7d observed = Matrix7d::Identity(), held = Matrix7d::Zero();
  for (int b = 0; b < 3; ++b) {
    CalibrationBlock block;
    block.offset = offsets[b];
    block.size = sizes[b];
    block.prior_information = estimate.prior_information.block(block.offset, block.offset, block.size, block.size);
    block.observed_std = observed_std[b];
    const Eigen::MatrixXd open = ObserveBlock(estimate.information, block).unobserved;
    estimate.observed_directions(b) = int(block.size - open.cols());
    change.segment(block.offset, block.size) -= open * (open.transpose() * change.segment(block.offset, block.size));
    observed.block(block.offset, block.offset, block.size, block.size) -= open * open.transpose();
    held.block(block.offset, block.offset, block.size, block.size) =
        open * open.transpose() / estimate.prior_information(block.offset, block.offset);
  }
  estimate.covariance = observed * estimate.information.inverse() * observed + held;
  const SE3d before = estimate.applied;
  const double clock_before = estimate.applied_clock;
  estimate.applied = SE3d(estimate.given.rotation() * SO3d::Exp(change.head<3>()),
                          estimate.given.translation() + change.segment<3>(3));
  estimate.applied_clock = change(6);
  return (before.Inverse() * estimate.applied).Log().norm() > 0.0 || clock_before != estimate.applied_clock;
}

RigOnlineCalibration::Vector7d RigOnlineCalibration::std(std::size_t r) const {
  return estimates_[r].covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
}

}  // namespace radargauss
