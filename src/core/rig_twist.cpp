// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/core/rig_twist.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <Eigen/LU>

namespace radargauss {

Eigen::Matrix<double, 1, 6> RigDopplerJacobian(const Eigen::Vector3d& position, const SE3d& body_from_radar) {
  const Eigen::Vector3d b = body_from_radar.rotation() * position.normalized();  // the direction, body frame
  Eigen::Matrix<double, 1, 6> row;
  row << -b.transpose(), -body_from_radar.translation().cross(b).transpose();
  return row;
}

Eigen::Vector3d RigRadarVelocity(const SE3d& body_from_radar, const Eigen::Vector3d& v, const Eigen::Vector3d& w) {
  return body_from_radar.rotation().Inverse() * (v + w.cross(body_from_radar.translation()));
}

double RigDoppler(const Eigen::Vector3d& position, const SE3d& body_from_radar, const Eigen::Vector3d& v,
                  const Eigen::Vector3d& w) {
  return -position.normalized().dot(RigRadarVelocity(body_from_radar, v, w));
}

Eigen::Matrix3Xd UnobservedRotations(const std::vector<SE3d>& body_from_radars) {
  if (body_from_radars.size() < 2) return Eigen::Matrix3d::Identity();
  // w x (t_i - t_0) = 0 for every i leaves w unobserved: w along every
  // lever-arm difference, so the differences' span decides.
  Eigen::Matrix3Xd differences(3, body_from_radars.size() - 1);
  double scale = 1.0;
  for (std::size_t i = 1; i < body_from_radars.size(); ++i) {
    differences.col(Eigen::Index(i - 1)) = body_from_radars[i].translation() - body_from_radars[0].translation();
    scale = std::max(scale, body_from_radars[i].translation().norm());
  }
  const Eigen::JacobiSVD<Eigen::Matrix3Xd> svd(differences, Eigen::ComputeFullU);
  const double floor = 1e-9 * scale;
  int rank = 0;
  for (Eigen::Index k = 0; k < svd.singularValues().size(); ++k) rank += svd.singularValues()(k) > floor;
  if (rank == 0) return Eigen::Matrix3d::Identity();
  if (rank == 1) {  // the line's direction, its largest component positive
    Eigen::Vector3d line = svd.matrixU().col(0);
    Eigen::Index largest = 0;
    line.cwiseAbs().maxCoeff(&largest);
    return line(largest) < 0.0 ? Eigen::Vector3d(-line) : line;
  }
  return Eigen::Matrix3Xd(3, 0);
}

namespace {

// The rig's gated points as rows of H [v; w] = y, with the radar and point of each.
struct RigRows {
  Eigen::Matrix<double, Eigen::Dynamic, 6> H;
  Eigen::VectorXd y;
  std::vector<std::pair<std::size_t, std::size_t>> source;  // (radar, point)
};

RigRows GatedRows(const std::vector<RigScan>& scans, const EgoVelocityOptions& options) {
  std::vector<Eigen::Matrix<double, 1, 6>> rows;
  std::vector<double> y;
  RigRows out;
  for (std::size_t r = 0; r < scans.size(); ++r) {
    const RadarScan& scan = *scans[r].scan;
    if (!scan.has_doppler) continue;
    for (std::size_t i = 0; i < scan.points.size(); ++i) {
      const RadarPoint& point = scan.points[i];
      const double range = point.position.norm();
      if (!(range >= options.min_range && range <= options.max_range) || !std::isfinite(point.doppler)) continue;
      rows.push_back(RigDopplerJacobian(point.position, scans[r].body_from_radar));
      y.push_back(point.doppler);
      out.source.emplace_back(r, i);
    }
  }
  out.H.resize(Eigen::Index(rows.size()), 6);
  out.y.resize(Eigen::Index(y.size()));
  for (std::size_t k = 0; k < rows.size(); ++k) {
    out.H.row(Eigen::Index(k)) = rows[k];
    out.y(Eigen::Index(k)) = y[k];
  }
  return out;
}

// RANSAC draws of `size` points: log(1 - p_success) / log(1 - (1 - p_outlier)^size).
int DrawsFor(int size, const EgoVelocityOptions& options) {
  const double clean = std::pow(1.0 - options.outlier_probability, size);
  if (clean >= 1.0) return 1;
  return std::max(1, int(std::ceil(std::log(1.0 - options.success_probability) / std::log(1.0 - clean))));
}

// The rows of largest support among seeded `size`-row draws of A z = y
// (the first of largest support), in row order. Each radar votes with the
// share of its points a hypothesis explains, and a draw takes a radar at
// random, then one of its points: a radar whose view a close car fills can
// neither outvote the others nor fill the draws with the car.
std::vector<Eigen::Index> LargestConsensus(const Eigen::MatrixXd& A, const Eigen::VectorXd& y,
                                           const std::vector<std::size_t>& radar_of_row, int draws,
                                           const EgoVelocityOptions& options,
                                           const std::function<bool(const Eigen::VectorXd&)>& admissible) {
  const Eigen::Index n = A.rows(), size = A.cols();
  std::vector<std::vector<Eigen::Index>> rows_of;  // per radar with rows
  std::vector<std::size_t> slot(*std::max_element(radar_of_row.begin(), radar_of_row.end()) + 1, SIZE_MAX);
  for (Eigen::Index k = 0; k < n; ++k) {
    std::size_t& s = slot[radar_of_row[std::size_t(k)]];
    if (s == SIZE_MAX) {
      s = rows_of.size();
      rows_of.emplace_back();
    }
    rows_of[s].push_back(k);
  }
  std::vector<double> vote(static_cast<std::size_t>(n));  // a row's vote: 1 / the points of its radar
  for (const std::vector<Eigen::Index>& rows : rows_of) {
    for (const Eigen::Index k : rows) vote[std::size_t(k)] = 1.0 / double(rows.size());
  }
  std::mt19937 rng(options.seed);
  std::uniform_int_distribution<std::size_t> pick_radar(0, rows_of.size() - 1);
  std::vector<Eigen::Index> drawn(std::size_t(size), 0);
  Eigen::VectorXd best_z;
  double best_votes = 0.0;
  for (int draw = 0; draw < draws; ++draw) {
    for (std::size_t k = 0; k < drawn.size(); ++k) {
      do {
        const std::vector<Eigen::Index>& rows = rows_of[pick_radar(rng)];
        drawn[k] = rows[std::uniform_int_distribution<std::size_t>(0, rows.size() - 1)(rng)];
      } while (std::find(drawn.begin(), drawn.begin() + std::ptrdiff_t(k), drawn[k]) !=
               drawn.begin() + std::ptrdiff_t(k));
    }
    Eigen::MatrixXd a(size, size);
    Eigen::VectorXd b(size);
    for (Eigen::Index k = 0; k < size; ++k) {
      a.row(k) = A.row(drawn[std::size_t(k)]);
      b(k) = y(drawn[std::size_t(k)]);
    }
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(a);
    if (lu.rank() < size) continue;  // points whose directions leave the twist open
    const Eigen::VectorXd z = lu.solve(b);
    if (!admissible(z)) continue;
    const Eigen::ArrayXd residual = (y - A * z).array().abs();
    double votes = 0.0;
    for (Eigen::Index k = 0; k < n; ++k) votes += residual(k) < options.inlier_threshold ? vote[std::size_t(k)] : 0.0;
    if (votes > best_votes) {
      best_votes = votes;
      best_z = z;
    }
  }
  std::vector<Eigen::Index> best;
  if (best_votes == 0.0) return best;
  const Eigen::VectorXd residual = (y - A * best_z).cwiseAbs();
  for (Eigen::Index k = 0; k < n; ++k) {
    if (residual(k) < options.inlier_threshold) best.push_back(k);
  }
  return best;
}

// Least squares on `inliers`, then on the points within the threshold of
// that fit, until the set holds (at most five fits): a draw's few noisy
// points pick a consensus biased towards themselves, which the refit sheds.
// False when the inliers leave a direction open.
bool RefitOnInliers(const Eigen::MatrixXd& A, const Eigen::VectorXd& y, double threshold,
                    std::vector<Eigen::Index>& inliers, Eigen::VectorXd& z, Eigen::MatrixXd& normal_inverse) {
  const Eigen::Index size = A.cols();
  constexpr int kRefits = 5;
  for (int refit = 0; refit < kRefits; ++refit) {
    Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(size, size);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(size);
    for (const Eigen::Index k : inliers) {
      normal += A.row(k).transpose() * A.row(k);
      rhs += A.row(k).transpose() * y(k);
    }
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(normal);
    if (lu.rank() < size) return false;
    z = lu.solve(rhs);
    normal_inverse = lu.inverse();
    std::vector<Eigen::Index> next;
    const Eigen::VectorXd residual = (y - A * z).cwiseAbs();
    for (Eigen::Index k = 0; k < A.rows(); ++k) {
      if (residual(k) < threshold) next.push_back(k);
    }
    if (next == inliers || next.size() <= std::size_t(size)) break;
    inliers = std::move(next);
  }
  return true;
}

}  // namespace

RigTwist EstimateRigTwist(const std::vector<RigScan>& scans, const RigTwistOptions& options) {
  RigTwist result;
  result.observed.setZero();
  for (const RigScan& s : scans) {
    if (!s.scan) throw std::invalid_argument("EstimateRigTwist: a radar's scan is null");
    result.inlier.emplace_back(s.scan->points.size(), false);
  }
  const RigRows rows = GatedRows(scans, options.doppler);
  if (rows.y.size() == 0) {
    result.reason = "no radar point with Doppler in the range gate";
    return result;
  }
  // The directions of [v; w] the rig's points observe: the eigenvectors of
  // H^T H whose singular value is not negligible against the largest.
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(rows.H.transpose() * rows.H);
  const Vector6d singular = eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  const double floor = options.min_relative_singular_value * singular.maxCoeff();
  std::vector<int> kept;
  for (int k = 0; k < 6; ++k) {
    if (singular(k) > floor) kept.push_back(k);
  }
  result.rank = int(kept.size());
  Eigen::MatrixXd basis(6, result.rank);  // V_o
  for (int k = 0; k < result.rank; ++k) basis.col(k) = eigen.eigenvectors().col(kept[std::size_t(k)]);
  if (rows.y.size() <= result.rank) {
    result.reason = "fewer Doppler points than the " + std::to_string(result.rank) + " directions they observe";
    return result;
  }
  const Eigen::MatrixXd A = rows.H * basis;  // the rows in the observed coordinates z, [v; w] = V_o z
  result.ransac_iterations = DrawsFor(result.rank, options.doppler);
  std::vector<std::size_t> radar_of_row;
  for (const auto& [radar, point] : rows.source) radar_of_row.push_back(radar);
  // A hypothesis whose velocity or rotation rate leaves its gate does not count.
  const auto admissible = [&](const Eigen::VectorXd& z) {
    const Vector6d twist = basis * z;
    return (!options.gate || options.gate->Admits(twist.head<3>())) &&
           (!options.angular_gate || options.angular_gate->Admits(twist.tail<3>()));
  };
  const std::vector<Eigen::Index> consensus =
      LargestConsensus(A, rows.y, radar_of_row, result.ransac_iterations, options.doppler, admissible);
  if (consensus.size() <= std::size_t(result.rank)) {
    result.reason = "no consensus: too few points agree on one twist";
    return result;
  }
  std::vector<Eigen::Index> inliers = consensus;
  Eigen::VectorXd z;
  Eigen::MatrixXd normal_inverse;
  if (!RefitOnInliers(A, rows.y, options.doppler.inlier_threshold, inliers, z, normal_inverse)) {
    result.reason = "the consensus points leave the twist open";
    return result;
  }
  if (!admissible(z)) {
    result.reason = "the twist left its gate";
    return result;
  }
  double sse = 0.0;
  for (const Eigen::Index k : inliers) sse += std::pow(rows.y(k) - A.row(k).dot(z), 2);
  const double dof = std::max(1.0, double(inliers.size()) - double(result.rank));
  const Vector6d twist = basis * z;
  result.velocity = twist.head<3>();
  result.angular_velocity = twist.tail<3>();
  result.covariance = basis * ((sse / dof) * normal_inverse) * basis.transpose();
  result.observed = basis * basis.transpose();
  for (const Eigen::Index k : inliers) {
    const auto& [radar, point] = rows.source[std::size_t(k)];
    result.inlier[radar][point] = true;
  }
  result.success = twist.allFinite();
  if (!result.success) result.reason = "the least-squares twist is not finite";
  return result;
}

}  // namespace radargauss
