// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/inertial_window.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <ceres/problem.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "radargauss/core/conventions.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/lie/manifold.hpp"
#include "radargauss/residuals/imu_preintegration.hpp"
#include "radargauss/residuals/imu_residual.hpp"
#include "radargauss/residuals/radar_inertial_residuals.hpp"
#include "radargauss/residuals/rotation_residual.hpp"
#include "radargauss/solvers/calibration_gate.hpp"
#include "radargauss/solvers/marginalization.hpp"
#include "radargauss/solvers/window_solvers.hpp"
#include "inertial_window_problem.hpp"

namespace radargauss {

using inertial_window::kElevationBiasPrior;

namespace {

constexpr double kClockRelinearisation = 0.002;  // s

// W with W^T W = information, for a positive semi-definite information.
Eigen::MatrixXd SqrtInformation(const Eigen::MatrixXd& information) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(0.5 * (information + information.transpose()));
  const Eigen::VectorXd roots = eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return roots.asDiagonal() * eigen.eigenvectors().transpose();
}

// r_i = (x_i - mean_i) / sigma_i on one Euclidean block: the first state's
// priors. (Not ceres::NormalPrior: its Eigen members are allocated inside
// Debian's library and would be freed here, which the address sanitizer
// refuses.)
class DiagonalPrior final : public ceres::CostFunction {
 public:
  DiagonalPrior(const Eigen::VectorXd& mean, const Eigen::VectorXd& sigma)
      : mean_(mean), weight_(sigma.cwiseInverse()) {
    set_num_residuals(int(mean.size()));
    mutable_parameter_block_sizes()->push_back(int(mean.size()));
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Eigen::Map<const Eigen::VectorXd> x(parameters[0], mean_.size());
    Eigen::Map<Eigen::VectorXd>(residuals, mean_.size()) = weight_.cwiseProduct(x - mean_);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(jacobians[0], mean_.size(),
                                                                                           mean_.size());
      J = weight_.asDiagonal();
    }
    return true;
  }

 private:
  Eigen::VectorXd mean_, weight_;
};

}  // namespace

InertialWindow::InertialWindow(const InertialWindowOptions& options, const SE3d& radar_from_imu)
    : options_(options), impl_(std::make_unique<Impl>()) {
  CheckOptions(InertialWindowOptionTable(), options);
  const SE3d imu_from_radar = radar_from_imu.Inverse();
  impl_->extrinsic_rotation = imu_from_radar.rotation().quaternion().coeffs();
  impl_->extrinsic_translation = imu_from_radar.translation();
  impl_->clock_offset[0] = impl_->clock_linearisation = options.clock_offset;
}

InertialWindow::~InertialWindow() = default;

void InertialWindow::AddImu(const std::vector<ImuSample>& samples) {
  std::vector<ImuSample>& imu = impl_->imu;
  for (const ImuSample& sample : samples) {
    if (!imu.empty() && !(sample.stamp > imu.back().stamp)) {
      throw DataError("IMU sample at " + std::to_string(sample.stamp) + " s does not follow the one at " +
                      std::to_string(imu.back().stamp) + " s");
    }
    imu.push_back(sample);
  }
}

void InertialWindow::Start(const InertialState& state) {
  if (!impl_->nodes.empty()) throw std::logic_error("InertialWindow::Start: the window has started");
  if (!state.pose.translation().allFinite() || !state.pose.rotation().quaternion().coeffs().allFinite() ||
      !state.velocity.allFinite() || !state.bias.gyro.allFinite() || !state.bias.accel.allFinite() ||
      !std::isfinite(state.stamp)) {
    throw std::invalid_argument("InertialWindow::Start: the first state is not finite");
  }
  Node node;
  node.stamp = state.stamp;
  node.rotation = state.pose.rotation().quaternion().coeffs();
  node.position = state.pose.translation();
  node.motion << state.velocity, state.bias.gyro, state.bias.accel;
  if (options_.vehicle_motion_std > 0.0) {
    node.vehicle = std::make_shared<VehicleMotionCostFunction>(options_.vehicle_motion_std);
  }
  impl_->nodes.push_back(node);
  Node& first = impl_->nodes.back();
  // Biases about zero, the velocity about the start's; the tilt and the clock offset about their starts.
  Eigen::Matrix<double, 9, 1> sigmas;
  sigmas << Eigen::Vector3d::Constant(options_.velocity_prior), Eigen::Vector3d::Constant(options_.gyro_bias_prior),
      Eigen::Vector3d::Constant(options_.accel_bias_prior);
  Eigen::Matrix<double, 9, 1> mean;
  mean << state.velocity, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero();
  first.first_priors.push_back({std::make_shared<DiagonalPrior>(mean, sigmas), {first.motion.data()}});
  if (options_.estimate_clock_offset) {
    // Unobservable while the drive is straight and even: held near its start until it turns.
    first.first_priors.push_back(
        {std::make_shared<DiagonalPrior>(Eigen::VectorXd::Constant(1, impl_->clock_offset[0]),
                                         Eigen::VectorXd::Constant(1, options_.clock_offset_prior)),
         {impl_->clock_offset}});
  }
  if (options_.estimate_extrinsic_rotation) {
    const RotationPrior prior{SO3d::FromXyzw(impl_->extrinsic_rotation.data()),
                              Eigen::Matrix3d::Identity() / (options_.extrinsic_rotation_prior_deg * M_PI / 180.0)};
    first.first_priors.push_back({std::make_shared<RotationCostFunction>(prior), {impl_->extrinsic_rotation.data()}});
  }
  if (options_.estimate_extrinsic_translation && options_.extrinsic_translation_prior > 0.0) {
    first.first_priors.push_back(
        {std::make_shared<DiagonalPrior>(impl_->extrinsic_translation,
                                         Eigen::Vector3d::Constant(options_.extrinsic_translation_prior)),
         {impl_->extrinsic_translation.data()}});
  }
  if (options_.estimate_elevation_bias) {
    first.first_priors.push_back(
        {std::make_shared<DiagonalPrior>(Eigen::VectorXd::Constant(1, impl_->elevation_bias[0]),
                                         Eigen::VectorXd::Constant(1, kElevationBiasPrior)),
         {impl_->elevation_bias}});
  }
  if (options_.estimate_tilt) {
    constexpr double kTiltPrior = 0.1;  // rad: the start's tilt from the accelerometer is this good at worst
    first.first_priors.push_back(
        {std::make_shared<DiagonalPrior>(impl_->tilt, Eigen::Vector2d::Constant(kTiltPrior)), {impl_->tilt.data()}});
  }
}

void InertialWindow::AddState(double stamp) {
  if (impl_->nodes.empty()) throw std::logic_error("InertialWindow::AddState before Start");
  const Node& last = impl_->nodes.back();
  if (!(stamp > last.stamp)) {
    throw DataError("state at " + std::to_string(stamp) + " s does not follow the one at " +
                    std::to_string(last.stamp) + " s");
  }
  if (options_.estimate_clock_offset) impl_->HoldClockOffsetFor(stamp);
  const double t0 = impl_->clock_linearisation;
  const ImuPreintegration between = Preintegrate(impl_->imu, last.stamp + t0, stamp + t0, last.Bias(), options_.noise);
  // The prediction (imu_preintegration.hpp's model) is the new state's start.
  const SE3d pose = last.State().pose;
  const ImuDelta& d = between.delta();
  const Eigen::Vector3d g(0.0, 0.0, -kGravity), v = last.motion.segment<3>(kMotionVelocity);
  Node node;
  node.stamp = stamp;
  node.rotation = (pose.rotation() * d.rotation).quaternion().coeffs();
  node.position =
      pose.translation() + v * d.duration + 0.5 * g * d.duration * d.duration + pose.rotation() * d.position;
  node.motion = last.motion;
  node.motion.segment<3>(kMotionVelocity) = v + g * d.duration + pose.rotation() * d.velocity;
  node.from_previous = between;
  node.imu = std::make_shared<ImuCostFunction>(between, options_.noise);
  if (options_.vehicle_motion_std > 0.0) {
    node.vehicle = std::make_shared<VehicleMotionCostFunction>(options_.vehicle_motion_std);
  }
  impl_->nodes.push_back(std::move(node));
}

void InertialWindow::AddPose(const SE3d& world_from_radar, const Eigen::Matrix<double, 6, 6>& information) {
  if (impl_->nodes.empty()) throw std::logic_error("InertialWindow::AddPose before Start");
  if (!world_from_radar.translation().allFinite() || !world_from_radar.rotation().quaternion().coeffs().allFinite() ||
      !information.allFinite()) {
    throw std::invalid_argument("InertialWindow::AddPose: a pose or information that is not finite");
  }
  Node& node = impl_->nodes.back();
  node.pose_measurement = std::make_pair(world_from_radar, Eigen::Matrix<double, 6, 6>(SqrtInformation(information)));
  impl_->MakeRadarTerms(node);
}

void InertialWindow::AddVelocity(const Eigen::Vector3d& radar_velocity, const Eigen::Matrix3d& covariance,
                                 double elevation_bias_removed) {
  if (impl_->nodes.empty()) throw std::logic_error("InertialWindow::AddVelocity before Start");
  if (!radar_velocity.allFinite() || !covariance.allFinite() || !std::isfinite(elevation_bias_removed)) {
    throw std::invalid_argument("InertialWindow::AddVelocity: a velocity or covariance that is not finite");
  }
  const Eigen::LLT<Eigen::Matrix3d> factor(covariance);
  if (factor.info() != Eigen::Success) throw std::invalid_argument("AddVelocity: covariance not positive definite");
  Node& node = impl_->nodes.back();
  node.velocity_measurement = Node::VelocityMeasurement{
      radar_velocity, SqrtInformation(factor.solve(Eigen::Matrix3d::Identity())), elevation_bias_removed};
  impl_->MakeRadarTerms(node);
}

std::size_t InertialWindow::size() const { return impl_->nodes.size(); }
InertialState InertialWindow::state(std::size_t index) const { return impl_->nodes.at(index).State(); }
InertialState InertialWindow::newest() const { return impl_->nodes.back().State(); }
Eigen::Vector2d InertialWindow::tilt() const { return impl_->tilt; }
double InertialWindow::clock_offset() const { return impl_->clock_offset[0]; }
double InertialWindow::elevation_bias() const { return impl_->elevation_bias[0]; }
void InertialWindow::set_tilt(const Eigen::Vector2d& roll_pitch) { impl_->tilt = roll_pitch; }

SE3d InertialWindow::radar_from_imu() const {
  return SE3d(SO3d::FromXyzw(impl_->extrinsic_rotation.data()), impl_->extrinsic_translation).Inverse();
}

SE3d InertialWindow::RadarPoseInMatcherWorld() const {
  const SE3d tilt(TiltRotation(impl_->tilt.data()), Eigen::Vector3d::Zero());
  return tilt * newest().pose * radar_from_imu().Inverse();
}

namespace {

ceres::Problem::Options BorrowingProblem() {
  ceres::Problem::Options options;
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return options;
}

}  // namespace

WindowSolveSummary InertialWindow::Solve() {
  const auto start = std::chrono::steady_clock::now();
  if (impl_->nodes.empty()) throw std::logic_error("InertialWindow::Solve before Start");
  std::deque<Node>& nodes = impl_->nodes;
  while (nodes.size() > options_.size) RemoveOldest();
  // A clock offset moved past kClockRelinearisation: every term read again
  // at it (the terms' first-order move d stays small).
  const double t0 = impl_->clock_offset[0];
  const bool clock_moved = std::abs(t0 - impl_->clock_linearisation) > kClockRelinearisation || impl_->clock_held;
  if (clock_moved) {
    impl_->clock_linearisation = t0;
    for (Node& node : nodes) impl_->MakeRadarTerms(node);
  }
  // The IMU terms whose bias moved past the first-order correction (or whose
  // clock did), integrated again.
  std::size_t reintegrated = 0;
  for (std::size_t k = 1; k < nodes.size(); ++k) {
    Node& node = nodes[k];
    if (!node.from_previous || (!clock_moved && node.from_previous->WithinCorrection(nodes[k - 1].Bias()))) continue;
    node.from_previous = Preintegrate(impl_->imu, nodes[k - 1].stamp + impl_->clock_linearisation,
                                      node.stamp + impl_->clock_linearisation, nodes[k - 1].Bias(), options_.noise);
    node.imu = std::make_shared<ImuCostFunction>(*node.from_previous, options_.noise);
    ++reintegrated;
  }
  ceres::Problem problem(BorrowingProblem());
  impl_->Build(problem, options_, nullptr);
  std::vector<std::unique_ptr<ceres::CostFunction>> holds;  // the gate's terms, for this solve only
  const bool calibrating = options_.estimate_extrinsic_rotation || options_.estimate_extrinsic_translation ||
                           options_.estimate_clock_offset || options_.estimate_elevation_bias;
  const CalibrationObservation calibration =
      calibrating ? impl_->ObserveCalibration(problem, options_, holds) : CalibrationObservation{};
  WindowSolveSummary summary =
      options_.solver == WindowSolver::kGaussNewton
          ? SolveWithGaussNewton(problem, impl_->VariableBlocks(options_), options_.max_iterations)
          : SolveWithCeres(problem, options_);
  summary.reintegrated = reintegrated;
  const bool held_after = options_.estimate_clock_offset && impl_->HoldClockOffsetInBounds();
  summary.clock_offset_held = std::exchange(impl_->clock_held, false) || held_after;
  summary.calibration = calibration;  // the values the window goes on with
  summary.calibration.radar_from_imu = radar_from_imu();
  summary.calibration.clock_offset_value = impl_->clock_offset[0];
  summary.calibration.elevation_bias_value = impl_->elevation_bias[0];
  summary.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

WindowUncertainty InertialWindow::Uncertainty() const {
  if (impl_->nodes.empty()) throw std::logic_error("InertialWindow::Uncertainty before Start");
  ceres::Problem problem(BorrowingProblem());
  impl_->Build(problem, options_, nullptr);
  std::vector<int> offset;
  const Eigen::MatrixXd covariance = GaussNewtonMatrix(problem, impl_->VariableBlocks(options_), offset)
                                         .completeOrthogonalDecomposition()
                                         .pseudoInverse();
  const auto std_of = [&](std::size_t block, int first, int n) {
    Eigen::VectorXd s(n);
    for (int i = 0; i < n; ++i)
      s(i) = std::sqrt(std::max(0.0, covariance(offset[block] + first + i, offset[block] + first + i)));
    return s;
  };
  WindowUncertainty u;
  const std::size_t motion = 3 * impl_->nodes.size() - 1;  // the newest state's [v; b_g; b_a]
  u.velocity = std_of(motion, kMotionVelocity, 3);
  u.gyro_bias = std_of(motion, kMotionGyroBias, 3);
  u.accel_bias = std_of(motion, kMotionAccelBias, 3);
  std::size_t global = 3 * impl_->nodes.size();
  if (options_.estimate_tilt) u.tilt = std_of(global++, 0, 2);
  if (options_.estimate_extrinsic_rotation) u.extrinsic_rotation = std_of(global++, 0, 3);
  if (options_.estimate_extrinsic_translation) u.extrinsic_translation = std_of(global++, 0, 3);
  if (options_.estimate_clock_offset) u.clock_offset = std_of(global++, 0, 1)(0);
  if (options_.estimate_elevation_bias) u.elevation_bias = std_of(global++, 0, 1)(0);
  return u;
}

// The oldest state leaves: its terms become a prior on what they share with
// the rest (the next state and the estimated globals), or are dropped.
void InertialWindow::RemoveOldest() {
  std::deque<Node>& nodes = impl_->nodes;
  if (options_.marginalize && nodes.size() > 1) {
    ceres::Problem problem(BorrowingProblem());
    std::vector<ceres::ResidualBlockId> terms;
    impl_->Build(problem, options_, &terms);
    Node& oldest = nodes.front();
    Node& next = nodes[1];
    std::vector<double*> kept = {next.rotation.data(), next.position.data(), next.motion.data()};
    for (double* global : impl_->GlobalBlocks(options_)) kept.push_back(global);
    impl_->prior =
        Marginalize(problem, terms, {oldest.rotation.data(), oldest.position.data(), oldest.motion.data()}, kept);
  }
  // The IMU samples before the new oldest state are not needed any more.
  const double keep_from = nodes[1].stamp + impl_->clock_linearisation - 0.2;  // room for the offset to move
  nodes.pop_front();
  nodes.front().from_previous.reset();
  nodes.front().imu.reset();
  std::vector<ImuSample>& imu = impl_->imu;
  auto first_needed = std::upper_bound(imu.begin(), imu.end(), keep_from,
                                       [](double t, const ImuSample& sample) { return t < sample.stamp; });
  if (first_needed != imu.begin()) --first_needed;
  imu.erase(imu.begin(), first_needed);
}

}  // namespace radargauss
