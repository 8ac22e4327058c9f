// SPDX-License-Identifier: BSD-3-Clause
#include "rig_reference_motion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <ceres/solver.h>

#include "radargauss/residuals/rig_doppler_residual.hpp"

namespace radargauss::rig_calibration {

// The gyro's rates in the reference radar's frame on the body's clock, each
// at its interval's middle (a sample holds the mean rate to the next), less
// the window's gyro bias at the nearest state; none where the window never
// started or dropped the IMU.
std::vector<GyroSample> GyroRatesOf(const InertialMotion& inertial, std::vector<ImuSample> imu) {
  std::vector<std::pair<double, Eigen::Vector3d>> biases;
  for (const std::optional<InertialState>& state : inertial.states()) {
    if (state) biases.emplace_back(state->stamp, state->bias.gyro);
  }
  if (inertial.imu_fault() || biases.empty()) return {};
  ScreenImuSamples(imu, inertial.options().window.noise);
  const SO3d reference_from_imu = inertial.window().radar_from_imu().rotation();
  const double offset = inertial.window().clock_offset();  // the IMU's stamps minus the body's clock
  std::vector<GyroSample> rates;
  std::size_t b = 0;
  for (std::size_t i = 0; i + 1 < imu.size(); ++i) {
    const double t = 0.5 * (imu[i].stamp + imu[i + 1].stamp) - offset;
    while (b + 1 < biases.size() && std::abs(biases[b + 1].first - t) <= std::abs(biases[b].first - t)) ++b;
    rates.push_back({t, reference_from_imu * (imu[i].angular_velocity - biases[b].second)});
  }
  return rates;
}

std::optional<ClusteredMoments> ClusteredByScan(ceres::Problem& problem, const std::vector<double*>& blocks,
                                                const std::vector<ceres::ResidualBlockId>& residuals,
                                                const std::vector<std::size_t>& scan_of) {
  using Vector7d = Eigen::Matrix<double, 7, 1>;
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = blocks;
  evaluate.residual_blocks = residuals;
  std::vector<double> values;
  ceres::CRSMatrix crs;
  problem.Evaluate(evaluate, nullptr, &values, nullptr, &crs);
  if (crs.num_cols != 7) return std::nullopt;
  ClusteredMoments moments{Eigen::Matrix<double, 7, 7>::Zero(), Eigen::Matrix<double, 7, 7>::Zero()};
  Vector7d gradient = Vector7d::Zero();
  int row = 0;
  for (std::size_t b = 0; b < residuals.size(); ++b) {
    const int size = problem.GetCostFunctionForResidualBlock(residuals[b])->num_residuals();
    for (int k = 0; k < size; ++k, ++row) {
      Vector7d j = Vector7d::Zero();
      for (int e = crs.rows[std::size_t(row)]; e < crs.rows[std::size_t(row) + 1]; ++e) {
        j(crs.cols[std::size_t(e)]) = crs.values[std::size_t(e)];
      }
      moments.information += j * j.transpose();
      gradient += j * values[std::size_t(row)];
    }
    if (b + 1 == residuals.size() || scan_of[b + 1] != scan_of[b]) {  // the scan's residuals end here
      moments.spread += gradient * gradient.transpose();
      gradient.setZero();
    }
  }
  return moments;
}

void SolveDense(ceres::Problem& problem, int max_iterations) {
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = max_iterations;
  solver.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
}

ReferenceMap BuildReferenceMap(const std::vector<RadarScan>& scans, const std::vector<SE3d>& poses,
                               const MapOptions& options) {
  const MapGeometry geometry = BuildMapGeometry(scans, poses, options);
  ReferenceMap map{GaussianIndex(geometry.map.gaussians),
                   std::vector<double>(geometry.map.gaussians.size(), std::numeric_limits<double>::infinity()),
                   std::vector<double>(geometry.map.gaussians.size(), -std::numeric_limits<double>::infinity())};
  for (std::size_t i = 0; i < geometry.association.size(); ++i) {
    if (geometry.association[i] < 0) continue;
    const std::size_t g = std::size_t(geometry.association[i]);
    const double stamp = scans[geometry.cloud.scan[i]].timestamp;
    map.first_seen[g] = std::min(map.first_seen[g], stamp);
    map.last_seen[g] = std::max(map.last_seen[g], stamp);
  }
  return map;
}

ceres::CostFunction* ReferenceMap::PointCost(const Eigen::Vector3d& point, double t, const SE3d& extrinsic,
                                             const SE3d& world_from_reference, const SE3d& reference_from_world,
                                             const ReferenceMotion& motion, double gate, double max_age) const {
  const int g = index.Associate(world_from_reference * (extrinsic * point), gate * gate);
  if (g < 0 || t < first_seen[std::size_t(g)] - max_age || t > last_seen[std::size_t(g)] + max_age) return nullptr;
  return new RigPointCostFunction(point, reference_from_world * index.Mean(std::size_t(g)),
                                  index.SqrtInformationT(std::size_t(g)) * world_from_reference.rotation().Matrix(),
                                  motion);
}

}  // namespace radargauss::rig_calibration
