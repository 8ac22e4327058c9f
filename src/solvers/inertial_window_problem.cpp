// SPDX-License-Identifier: BSD-3-Clause
// The inertial window's problem (src/solvers/inertial_window_problem.hpp).
#include "inertial_window_problem.hpp"

#include <algorithm>
#include <string>

#include "radargauss/core/conventions.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/solvers/calibration_gate.hpp"

namespace radargauss {

using inertial_window::kElevationBiasPrior;

ImuAtScan InertialWindow::Impl::ImuAt(double stamp) const {
  const double t = stamp + clock_linearisation;
  auto after =
      std::upper_bound(imu.begin(), imu.end(), t, [](double s, const ImuSample& sample) { return s < sample.stamp; });
  if (after != imu.begin()) --after;
  if (after == imu.end()) throw DataError("no IMU sample at " + std::to_string(t) + " s");
  return {after->angular_velocity, after->specific_force, clock_linearisation};
}

void InertialWindow::Impl::MakeRadarTerms(Node& node) const {
  if (node.pose_measurement) {
    node.pose = std::make_shared<RadarPoseCostFunction>(node.pose_measurement->first, node.pose_measurement->second,
                                                        ImuAt(node.stamp));
  }
  if (node.velocity_measurement) {
    const Node::VelocityMeasurement& m = *node.velocity_measurement;
    node.velocity = std::make_shared<RadarVelocityCostFunction>(m.velocity, m.sqrt_information, ImuAt(node.stamp),
                                                                m.elevation_bias_removed);
  }
}

std::vector<double*> InertialWindow::Impl::VariableBlocks(const InertialWindowOptions& options) {
  std::vector<double*> blocks;
  for (Node& node : nodes) {
    blocks.insert(blocks.end(), {node.rotation.data(), node.position.data(), node.motion.data()});
  }
  for (double* global : GlobalBlocks(options)) blocks.push_back(global);
  return blocks;
}

std::vector<double*> InertialWindow::Impl::GlobalBlocks(const InertialWindowOptions& options) {
  std::vector<double*> blocks;
  if (options.estimate_tilt) blocks.push_back(tilt.data());
  if (options.estimate_extrinsic_rotation) blocks.push_back(extrinsic_rotation.data());
  if (options.estimate_extrinsic_translation) blocks.push_back(extrinsic_translation.data());
  if (options.estimate_clock_offset) blocks.push_back(clock_offset);
  if (options.estimate_elevation_bias) blocks.push_back(elevation_bias);
  return blocks;
}

std::pair<double, double> InertialWindow::Impl::ClockOffsetBounds(double newest) const {
  return {std::max(-kMaxClockOffset, imu.front().stamp - nodes.front().stamp),
          std::min(kMaxClockOffset, imu.back().stamp - newest)};
}

void InertialWindow::Impl::HoldClockOffsetFor(double stamp) {
  const auto [lowest, highest] = ClockOffsetBounds(stamp);
  if (std::max(clock_offset[0], clock_linearisation) <= highest || highest < lowest) return;
  clock_offset[0] = std::min(clock_offset[0], highest);
  clock_linearisation = std::min(clock_linearisation, highest);
  clock_held = true;
}

bool InertialWindow::Impl::HoldClockOffsetInBounds() {
  const auto [lowest, highest] = ClockOffsetBounds(nodes.back().stamp);
  double& offset = clock_offset[0];
  if (lowest > highest || (offset >= lowest && offset <= highest)) return false;
  offset = std::clamp(offset, lowest, highest);
  return true;
}

void InertialWindow::Impl::Build(ceres::Problem& problem, const InertialWindowOptions& options,
                                 std::vector<ceres::ResidualBlockId>* oldest_terms) {
  for (Node& node : nodes) {
    problem.AddParameterBlock(node.rotation.data(), 4, &so3);
    problem.AddParameterBlock(node.position.data(), 3);
    problem.AddParameterBlock(node.motion.data(), 9);
  }
  problem.AddParameterBlock(extrinsic_rotation.data(), 4, &so3);
  problem.AddParameterBlock(extrinsic_translation.data(), 3);
  problem.AddParameterBlock(tilt.data(), 2);
  problem.AddParameterBlock(clock_offset, 1);
  problem.AddParameterBlock(elevation_bias, 1);
  if (!options.estimate_clock_offset) problem.SetParameterBlockConstant(clock_offset);
  if (!options.estimate_elevation_bias) problem.SetParameterBlockConstant(elevation_bias);
  if (!options.estimate_extrinsic_rotation) problem.SetParameterBlockConstant(extrinsic_rotation.data());
  if (!options.estimate_extrinsic_translation) problem.SetParameterBlockConstant(extrinsic_translation.data());
  if (!options.estimate_tilt) problem.SetParameterBlockConstant(tilt.data());
  std::vector<ceres::ResidualBlockId> ids;  // the terms on the oldest state
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    Node& node = nodes[k];
    const auto on_oldest = [&](ceres::ResidualBlockId id, bool touches_oldest) {
      if (touches_oldest) ids.push_back(id);
    };
    for (auto& [cost, blocks] : node.first_priors) {
      on_oldest(problem.AddResidualBlock(cost.get(), nullptr, blocks), k == 0);
    }
    if (node.pose) {
      on_oldest(problem.AddResidualBlock(
                    node.pose.get(), nullptr,
                    {node.rotation.data(), node.position.data(), node.motion.data(), extrinsic_rotation.data(),
                     extrinsic_translation.data(), tilt.data(), clock_offset}),
                k == 0);
    }
    if (node.velocity) {
      on_oldest(problem.AddResidualBlock(node.velocity.get(), nullptr,
                                         {node.rotation.data(), node.motion.data(), extrinsic_rotation.data(),
                                          extrinsic_translation.data(), clock_offset, elevation_bias}),
                k == 0);
    }
    if (node.vehicle) {
      on_oldest(problem.AddResidualBlock(node.vehicle.get(), nullptr, node.rotation.data(), node.motion.data()),
                k == 0);
    }
    if (k > 0 && node.imu) {
      Node& before = nodes[k - 1];
      on_oldest(problem.AddResidualBlock(node.imu.get(), nullptr,
                                         {before.rotation.data(), before.position.data(), before.motion.data(),
                                          node.rotation.data(), node.position.data(), node.motion.data()}),
                k == 1);
    }
  }
  if (prior) ids.push_back(problem.AddResidualBlock(prior.get(), nullptr, prior->parameter_blocks()));
  if (oldest_terms != nullptr) *oldest_terms = ids;
}

CalibrationObservation InertialWindow::Impl::ObserveCalibration(
    ceres::Problem& problem, const InertialWindowOptions& options,
    std::vector<std::unique_ptr<ceres::CostFunction>>& holds) {
  CalibrationObservation result;
  struct Estimated {
    bool on;
    GatedBlock block;
    int* directions;  // where the result goes
    double* std;
  };
  const Estimated table[] = {
      {options.estimate_extrinsic_rotation,
       {extrinsic_rotation.data(), 3, true, options.extrinsic_rotation_prior_deg * M_PI / 180.0,
        options.observed_rotation_std_deg * kRadiansPerDegree},
       &result.extrinsic_rotation,
       result.extrinsic_rotation_std.data()},
      {options.estimate_extrinsic_translation,
       {extrinsic_translation.data(), 3, false, options.extrinsic_translation_prior, options.observed_translation_std},
       &result.extrinsic_translation,
       result.extrinsic_translation_std.data()},
      {options.estimate_clock_offset,
       {clock_offset, 1, false, options.clock_offset_prior, options.observed_clock_std},
       &result.clock_offset,
       &result.clock_offset_std},
      {options.estimate_elevation_bias,
       {elevation_bias, 1, false, kElevationBiasPrior, options.observed_elevation_bias_std_deg * kRadiansPerDegree},
       &result.elevation_bias,
       &result.elevation_bias_std},
  };
  std::vector<GatedBlock> gated;
  std::vector<const Estimated*> estimated;
  for (const Estimated& e : table) {
    if (!e.on) continue;
    gated.push_back(e.block);
    estimated.push_back(&e);
  }
  const std::vector<BlockObservation> observed =
      GateCalibration(problem, VariableBlocks(options), gated, options.calibration_gate, holds);
  for (std::size_t k = 0; k < estimated.size(); ++k) {
    const int size = estimated[k]->block.size;
    *estimated[k]->directions = size - int(observed[k].unobserved.cols());
    Eigen::Map<Eigen::VectorXd>(estimated[k]->std, size) = observed[k].std();
  }
  return result;
}

}  // namespace radargauss
