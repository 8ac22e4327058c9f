// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/core/doppler.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "radargauss/core/voxel_grid.hpp"

namespace radargauss {

const OptionTable<EgoVelocityOptions>& EgoVelocityOptionTable() {
  using O = EgoVelocityOptions;
  static const OptionTable<O> table = {
      RADARGAUSS_OPTION(O, "ego_min_range", min_range).AtLeast(0.0).Unit("m").Help("Doppler filter's range gate"),
      RADARGAUSS_OPTION(O, "ego_max_range", max_range)
          .Above(0.0)
          .Unit("m")
          .NotBelow("ego_min_range")
          .Help("and its far end"),
      RADARGAUSS_OPTION(O, "ego_outlier_probability", outlier_probability)
          .In(0.0, 0.9)
          .Help("RANSAC: expected outlier share"),
      RADARGAUSS_OPTION(O, "ego_success_probability", success_probability)
          .In(0.5, 0.999999)
          .Help("RANSAC: wanted chance of one clean draw"),
      RADARGAUSS_OPTION(O, "ego_inlier_threshold", inlier_threshold)
          .Above(0.0)
          .Unit("m/s")
          .Help("|v_d - H v| of an inlier"),
      RADARGAUSS_OPTION(O, "ego_zero_velocity_threshold", zero_velocity_threshold)
          .AtLeast(0.0)
          .Unit("m/s")
          .Help("75th percentile of |v_d| below it: standing"),
      RADARGAUSS_OPTION(O, "ego_zero_velocity_sigma", zero_velocity_sigma)
          .Above(0.0)
          .Unit("m/s")
          .Help("velocity std when standing"),
      RADARGAUSS_OPTION(O, "seed", seed).Help("seed of the Doppler RANSAC"),
      RADARGAUSS_OPTION(O, "ego_consensus_voxel", consensus_voxel)
          .AtLeast(0.0)
          .Unit("m")
          .Help("support counted in voxels of this edge (0: points)"),
  };
  return table;
}

double VelocityGateWidth(const Eigen::Matrix3d& covariance, double dt, double gate_sigmas, double acceleration_std,
                         double min_gate) {
  const double spread = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvalues().maxCoeff();
  return std::max(min_gate, gate_sigmas * std::sqrt(std::max(spread, 0.0) + std::pow(acceleration_std * dt, 2)));
}

int RansacIterations(double outlier_probability, double success_probability) {
  const double clean_draw = std::pow(1.0 - outlier_probability, 3);
  if (clean_draw >= 1.0) return 1;  // no outliers expected: one draw suffices
  return std::max(1, static_cast<int>(std::ceil(std::log(1.0 - success_probability) / std::log(1.0 - clean_draw))));
}

namespace {

// Least squares on the rows `rows` of (H, y): v, sigma^2 (H^T H)^-1.
bool SolveLeastSquares(const Eigen::MatrixX3d& H, const Eigen::VectorXd& y, const std::vector<int>& rows,
                       Eigen::Vector3d& v, Eigen::Matrix3d& cov) {
  Eigen::Matrix3d hth = Eigen::Matrix3d::Zero();
  Eigen::Vector3d hty = Eigen::Vector3d::Zero();
  for (const int i : rows) {
    hth += H.row(i).transpose() * H.row(i);
    hty += H.row(i).transpose() * y[i];
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(hth);
  if (ldlt.info() != Eigen::Success || !(std::abs(hth.determinant()) > 1e-12)) return false;
  v = ldlt.solve(hty);
  double sse = 0.0;
  for (const int i : rows) sse += std::pow(y[i] - H.row(i).dot(v), 2);
  const double dof = std::max<double>(1.0, static_cast<double>(rows.size()) - 3.0);
  cov = (sse / dof) * hth.inverse();
  return v.allFinite();
}

// The rows of H v = y regrouped voxel by voxel (`opens` marks each voxel's
// first row), so that a hypothesis's voxels are counted in one pass without
// branches or lookups; without voxels, the rows as they are.
struct VoxelOrderedRows {
  std::vector<int> row_of;  // the row of H at each position
  std::vector<char> opens;
  std::vector<double> hx, hy, hz, y;
};

VoxelOrderedRows RegroupByVoxel(const Eigen::MatrixX3d& H, const Eigen::VectorXd& y,
                                const std::vector<std::vector<std::uint32_t>>& voxels) {
  const int n = static_cast<int>(y.size());
  VoxelOrderedRows rows{std::vector<int>(n),    std::vector<char>(n, 0), std::vector<double>(n),
                        std::vector<double>(n), std::vector<double>(n),  std::vector<double>(n)};
  std::vector<int>& row_of = rows.row_of;
  if (voxels.empty()) {
    for (int k = 0; k < n; ++k) row_of[k] = k;
  } else {
    int k = 0;
    for (const std::vector<std::uint32_t>& members : voxels) {
      rows.opens[k] = 1;
      for (const std::uint32_t row : members) row_of[k++] = int(row);
    }
  }
  for (int k = 0; k < n; ++k) {
    rows.hx[k] = H(row_of[k], 0), rows.hy[k] = H(row_of[k], 1), rows.hz[k] = H(row_of[k], 2);
    rows.y[k] = y[row_of[k]];
  }
  return rows;
}

// RANSAC over 3-point draws of the rows of H v = y: the consensus set (row
// indices) of largest support over `iterations` counted draws. Support is the
// number of rows, or with options.consensus_voxel > 0 the number of voxels
// they occupy (`voxels`: the rows of each, GroupByVoxel), then the number of rows.
std::vector<int> LargestConsensus(const Eigen::MatrixX3d& H, const Eigen::VectorXd& y,
                                  const EgoVelocityOptions& options, int iterations,
                                  const std::optional<VelocityGate>& gate,
                                  const std::vector<std::vector<std::uint32_t>>& voxels) {
  const int n = static_cast<int>(y.size());
  const int voxel_count = static_cast<int>(voxels.size());
  const VoxelOrderedRows rows = RegroupByVoxel(H, y, voxels);
  int best_voxels = 0;
  std::mt19937 rng(options.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  // With voxels, a draw takes three distinct voxels, then a row of each:
  // the world's many sparse voxels are drawn as often as a car's few dense ones.
  const bool by_voxel = voxel_count >= 3;
  std::uniform_int_distribution<int> pick_voxel(0, std::max(0, voxel_count - 1));
  const auto row_in = [&](int voxel) {
    const std::vector<std::uint32_t>& members = voxels[voxel];
    return int(members[std::uniform_int_distribution<std::size_t>(0, members.size() - 1)(rng)]);
  };
  // |y - H v| at each position (a loop the compiler vectorises).
  const auto residuals = [&rows, n](const Eigen::Vector3d& v, std::vector<double>& residual) {
    const double *hx = rows.hx.data(), *hy = rows.hy.data(), *hz = rows.hz.data(), *y0 = rows.y.data();
    for (int k = 0; k < n; ++k) residual[k] = std::abs(y0[k] - (hx[k] * v.x() + hy[k] * v.y() + hz[k] * v.z()));
  };
  // Hypotheses the gate turns away do not count: up to kGatedDrawFactor
  // times as many draws find the world's hypotheses among a car's.
  constexpr int kGatedDrawFactor = 50;
  int counted = 0;
  std::vector<Eigen::Vector3d> hypotheses;
  for (int draw = 0; counted < iterations && draw < kGatedDrawFactor * iterations; ++draw) {
    int a, b, c;
    if (by_voxel) {
      int va = pick_voxel(rng), vb = pick_voxel(rng), vc = pick_voxel(rng);
      while (vb == va) vb = pick_voxel(rng);
      while (vc == va || vc == vb) vc = pick_voxel(rng);
      a = row_in(va), b = row_in(vb), c = row_in(vc);
    } else {
      a = pick(rng), b = pick(rng), c = pick(rng);
      while (b == a) b = pick(rng);
      while (c == a || c == b) c = pick(rng);
    }
    Eigen::Matrix3d h;
    h << H.row(a), H.row(b), H.row(c);
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(h);
    if (!lu.isInvertible() || std::abs(h.determinant()) < 1e-6) {
      ++counted;
      continue;
    }
    const Eigen::Vector3d v = lu.solve(Eigen::Vector3d(y[a], y[b], y[c]));
    if (gate && !gate->Admits(v)) continue;
    ++counted;
    hypotheses.push_back(v);
  }
  // The draws depend on the generator and the gate alone, so their supports
  // are counted side by side. Without branches (whether a row is an inlier
  // is a coin toss to the branch predictor).
  struct Support {
    std::size_t size = 0;
    int covered = 0;
  };
  std::vector<Support> support(hypotheses.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, hypotheses.size(), 8), [&](const auto& range) {
    std::vector<double> residual(n);
    for (std::size_t h = range.begin(); h < range.end(); ++h) {
      residuals(hypotheses[h], residual);
      std::size_t size = 0;
      int covered = 0;
      int voxel_has_inlier = 0;
      for (int k = 0; k < n; ++k) {
        const int inlier = residual[k] < options.inlier_threshold;
        voxel_has_inlier &= rows.opens[k] ^ 1;
        size += std::size_t(inlier);
        covered += inlier & (voxel_has_inlier ^ 1);
        voxel_has_inlier |= inlier;
      }
      support[h] = {size, covered};
    }
  });
  // The first of largest support, as counting one after another finds it.
  std::size_t best_size = 0;
  Eigen::Vector3d best_velocity = Eigen::Vector3d::Zero();
  for (std::size_t h = 0; h < hypotheses.size(); ++h) {
    const auto [size, covered] = support[h];
    const bool wins =
        voxels.empty() ? size > best_size : covered > best_voxels || (covered == best_voxels && size > best_size);
    if (!wins) continue;
    best_voxels = covered;
    best_size = size;
    best_velocity = hypotheses[h];
  }
  // The winner's rows, in row order.
  std::vector<int> best;
  if (best_size == 0) return best;
  std::vector<double> residual(n);
  residuals(best_velocity, residual);
  std::vector<char> inlier(n, 0);
  for (int k = 0; k < n; ++k) inlier[rows.row_of[k]] = residual[k] < options.inlier_threshold;
  for (int row = 0; row < n; ++row) {
    if (inlier[row]) best.push_back(row);
  }
  return best;
}

}  // namespace

EgoVelocityResult EstimateEgoVelocity(const RadarScan& scan, const EgoVelocityOptions& options,
                                      const std::optional<VelocityGate>& gate) {
  EgoVelocityResult result;
  result.inlier.assign(scan.points.size(), false);
  if (!scan.has_doppler) {
    result.reason = "scan has no Doppler field";
    return result;
  }
  // Range gate; rows of H v = y for the gated points.
  std::vector<int> gated;
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const double range = scan.points[i].position.norm();
    if (range >= options.min_range && range <= options.max_range && std::isfinite(scan.points[i].doppler)) {
      gated.push_back(static_cast<int>(i));
    }
  }
  const int n = static_cast<int>(gated.size());
  if (n < 3) {
    result.reason = "fewer than 3 points in the range gate (" + std::to_string(n) + ")";
    return result;
  }
  Eigen::MatrixX3d H(n, 3);
  Eigen::VectorXd y(n);
  for (int k = 0; k < n; ++k) {
    const RadarPoint& p = scan.points[gated[k]];
    H.row(k) = -p.position.normalized().transpose();
    y[k] = p.doppler;
  }

  // Zero-velocity check: the 75th percentile of |v_d|.
  std::vector<double> abs_doppler(n);
  for (int k = 0; k < n; ++k) abs_doppler[k] = std::abs(y[k]);
  std::vector<double> sorted = abs_doppler;
  const std::size_t q75 = static_cast<std::size_t>(0.75 * (n - 1));
  std::nth_element(sorted.begin(), sorted.begin() + q75, sorted.end());
  if (sorted[q75] < options.zero_velocity_threshold && (!gate || gate->Admits(Eigen::Vector3d::Zero()))) {
    result.success = true;
    result.zero_velocity = true;
    result.covariance = std::pow(options.zero_velocity_sigma, 2) * Eigen::Matrix3d::Identity();
    for (int k = 0; k < n; ++k) {
      result.inlier[gated[k]] = abs_doppler[k] < options.zero_velocity_threshold;
    }
    return result;
  }

  // RANSAC over 3-point draws, keeping the largest consensus set.
  result.ransac_iterations = RansacIterations(options.outlier_probability, options.success_probability);
  std::vector<std::vector<std::uint32_t>> voxels;
  if (options.consensus_voxel > 0.0) {
    std::vector<Eigen::Vector3d> positions(n);
    for (int k = 0; k < n; ++k) positions[k] = scan.points[gated[k]].position;
    voxels = GroupByVoxel(positions, options.consensus_voxel);
  }
  const std::vector<int> best = LargestConsensus(H, y, options, result.ransac_iterations, gate, voxels);
  if (best.size() < 3) {
    result.reason = gate ? "RANSAC found no consensus of 3 or more points within the prediction gate"
                         : "RANSAC found no consensus of 3 or more points";
    return result;
  }
  // Least-squares refit on all inliers, then the final inlier set.
  if (!SolveLeastSquares(H, y, best, result.velocity, result.covariance)) {
    result.reason = "least-squares refit is singular";
    return result;
  }
  for (int k = 0; k < n; ++k) {
    result.inlier[gated[k]] = std::abs(y[k] - H.row(k).dot(result.velocity)) < options.inlier_threshold;
  }
  result.success = true;
  return result;
}

}  // namespace radargauss
