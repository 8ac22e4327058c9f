// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/map/rcs_model.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include <Eigen/QR>

#include "radargauss/core/stats.hpp"

namespace radargauss {

const OptionTable<RcsFitOptions>& RcsFitOptionTable() {
  using O = RcsFitOptions;
  static const OptionTable<O> table = {
      RADARGAUSS_OPTION(O, "degree", max_degree).In(0, kMaxShDegree).Help("SH degree of the RCS models"),
      RADARGAUSS_OPTION(O, "rcs_adaptive", adaptive).Help("lower the degree when members are too few (else no model)"),
      RADARGAUSS_CHOICE(O, "incidence", incidence, IncidenceModelNames(), IncidenceModelFromString)
          .Help("incidence vector of the RCS models: offset (the paper) or view"),
      RADARGAUSS_OPTION(O, "rcs_rank_threshold", rank_threshold)
          .In(0.0, 1.0)
          .Above(0.0)
          .Help("relative pivot threshold of the fit"),
      RADARGAUSS_OPTION(O, "rcs_min_explained", min_explained)
          .In(0.0, 1.0)
          .Help("a model whose view explains less of its RCS variance (adjusted R^2) is constant"),
  };
  return table;
}

RcsNormalisation NormaliseRcs(std::vector<double> rcs) {
  RcsNormalisation result;
  if (rcs.size() < 2) return result;
  std::sort(rcs.begin(), rcs.end());
  result.median = MedianOfSorted(rcs);
  result.scale = std::min(result.median - rcs.front(), rcs.back() - result.median);
  result.valid = result.scale > 0.0;
  return result;
}

void SetRcsFitSpread(RcsModel& model, double residual_sq, double total_sq, std::size_t inliers, int coefficients) {
  const double n = double(inliers), p = double(coefficients);
  if (n > p) {
    model.spread_db = model.scale * std::sqrt(std::max(residual_sq, 0.0) / (n - p));
    const double adjusted = total_sq > 0.0 ? 1.0 - (residual_sq / (n - p)) / (total_sq / (n - 1.0)) : 0.0;
    model.explained = std::clamp(adjusted, 0.0, 1.0);
  } else {
    model.spread_db = model.scale;
    model.explained = 0.0;
  }
}

RcsModel FitRcsModel(const std::vector<Eigen::Vector3d>& directions, const std::vector<double>& rcs,
                     const RcsFitOptions& options) {
  RcsModel model;
  const RcsNormalisation normalisation = NormaliseRcs(rcs);
  if (!normalisation.valid) return model;
  model.median = normalisation.median;
  model.scale = normalisation.scale;
  std::vector<int> inliers;
  for (std::size_t i = 0; i < rcs.size(); ++i) {
    if (std::abs(rcs[i] - model.median) <= model.scale) inliers.push_back(int(i));
  }
  const int n = int(inliers.size());
  Eigen::VectorXd y(n);
  Eigen::MatrixXd basis(n, ShCoefficientCount(kMaxShDegree));
  for (int k = 0; k < n; ++k) {
    y[k] = model.Normalise(rcs[inliers[k]]);
    double values[ShCoefficientCount(kMaxShDegree)];
    EvaluateShBasis<kMaxShDegree>(directions[inliers[k]], values);
    for (int j = 0; j < ShCoefficientCount(kMaxShDegree); ++j) basis(k, j) = values[j];
  }
  return FitAdaptiveDegree(model, std::size_t(n), options, [&](int degree, RcsModel& fit) {
    const int count = ShCoefficientCount(degree);
    const Eigen::MatrixXd A = basis.leftCols(count);
    // Rank-revealing least squares: the minimum-norm solution with the
    // directions whose pivots fall below the threshold truncated, so an
    // ill-determined combination gets no weight instead of a huge one.
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
    cod.setThreshold(options.rank_threshold);
    cod.compute(A);
    if (cod.rank() < std::max(1, count / 2) && options.adaptive) return false;
    const Eigen::VectorXd c = cod.solve(y);
    fit.degree = degree;
    fit.coefficients.fill(0.0);
    for (int j = 0; j < count; ++j) fit.coefficients[j] = c[j];
    const Eigen::VectorXd fitted = A * c;
    fit.fit_rmse = std::sqrt((fitted - y).squaredNorm() / n);
    fit.inliers = std::uint32_t(n);
    SetRcsFitSpread(fit, (fitted - y).squaredNorm(), (y.array() - y.mean()).square().sum(), std::size_t(n), count);
    // 10 log10 of the mean of 10^((rcs - prediction) / 10): the inliers'
    // linear mean over the model's dB value.
    double linear_sum = 0.0;
    for (int k = 0; k < n; ++k) linear_sum += std::pow(10.0, fit.scale * (y[k] - fitted[k]) / 10.0);
    fit.mean_offset_db = 10.0 * std::log10(linear_sum / n);
    return true;
  });
}

RcsModel FitAdaptiveDegree(RcsModel model, std::size_t inliers, const RcsFitOptions& options,
                           const std::function<bool(int degree, RcsModel& model)>& fit_at) {
  for (int degree = options.max_degree; degree >= 0; --degree) {
    if (inliers >= std::size_t(ShCoefficientCount(degree)) && fit_at(degree, model)) {
      // Not view-dependent beyond its noise: the constant model instead.
      if (degree > 0 && model.explained < options.min_explained) {
        degree = 1;
        continue;
      }
      return model;
    }
    if (!options.adaptive) break;
  }
  model.degree = -1;
  return model;
}

namespace {

// -1 for an empty bin (RcsFitStats).
double MedianOf(std::vector<double> values) { return values.empty() ? -1.0 : Median(std::move(values)); }

// The bin of `value` among lower edges `edges`.
template <std::size_t N>
std::size_t BinOf(const std::array<double, N>& edges, double value) {
  std::size_t bin = 0;
  while (bin + 1 < N && value >= edges[bin + 1]) ++bin;
  return bin;
}

void SetMemberSpreads(const std::vector<Eigen::Vector3d>& spreads, RcsFitStats& stats) {
  std::array<std::vector<double>, 4> by_range;
  std::array<std::vector<double>, 3> by_azimuth;
  std::vector<double> all;
  for (const Eigen::Vector3d& s : spreads) {
    if (std::isnan(s.x())) continue;
    all.push_back(s.x());
    by_range[BinOf(RcsFitStats::kRangeBins, s.y())].push_back(s.x());
    by_azimuth[BinOf(RcsFitStats::kAzimuthBins, s.z())].push_back(s.x());
  }
  stats.member_spread = MedianOf(all);
  for (std::size_t b = 0; b < by_range.size(); ++b) stats.member_spread_by_range[b] = MedianOf(by_range[b]);
  for (std::size_t b = 0; b < by_azimuth.size(); ++b) stats.member_spread_by_azimuth[b] = MedianOf(by_azimuth[b]);
}

}  // namespace

RcsFitStats FitRcsModels(GaussianMap& map, const MapCloud& cloud, const std::vector<int>& association,
                         const RcsFitOptions& options) {
  map.incidence = options.incidence;
  const std::size_t n_gaussians = map.gaussians.size();
  // Members of each Gaussian, in point order (CSR).
  std::vector<std::uint32_t> offsets(n_gaussians + 1, 0);
  for (const int g : association) {
    if (g >= 0) ++offsets[g + 1];
  }
  for (std::size_t g = 0; g < n_gaussians; ++g) offsets[g + 1] += offsets[g];
  std::vector<std::uint32_t> members(offsets.back());
  std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
  for (std::size_t i = 0; i < association.size(); ++i) {
    if (association[i] >= 0) members[fill[association[i]]++] = std::uint32_t(i);
  }
  // Per Gaussian: its members' RCS std, mean range and mean |azimuth| (NaN: too few members).
  std::vector<Eigen::Vector3d> member_spreads(n_gaussians, Eigen::Vector3d::Constant(std::nan("")));
  tbb::parallel_for(std::size_t(0), n_gaussians, [&](std::size_t g) {
    Gaussian& gaussian = map.gaussians[g];
    std::vector<Eigen::Vector3d> directions;
    std::vector<double> rcs;
    double range_sum = 0.0, azimuth_sum = 0.0;
    for (std::uint32_t k = offsets[g]; k < offsets[g + 1]; ++k) {
      const std::uint32_t i = members[k];
      const SE3d& pose = cloud.poses[cloud.scan[i]];
      const SE3d world_to_radar = pose.Inverse();
      const Eigen::Vector3d point_radar = world_to_radar * cloud.points[i];
      const Eigen::Vector3d mean_radar = world_to_radar * gaussian.mean;
      const Eigen::Vector3d u = IncidenceVector(options.incidence, point_radar, mean_radar);
      if (u.squaredNorm() < 1e-18) continue;  // no direction: skip the member
      directions.push_back(FacingSign(u) * u.normalized());
      rcs.push_back(cloud.rcs[i]);
      range_sum += point_radar.norm();
      azimuth_sum += std::abs(std::atan2(point_radar.y(), point_radar.x())) * 180.0 / M_PI;
    }
    if (cloud.has_rcs && rcs.size() >= RcsFitStats::kSpreadMinMembers) {
      const double n = double(rcs.size());
      double mean = 0.0, square = 0.0;
      for (const double x : rcs) mean += x / n;
      for (const double x : rcs) square += (x - mean) * (x - mean);
      member_spreads[g] = Eigen::Vector3d(std::sqrt(square / (n - 1.0)), range_sum / n, azimuth_sum / n);
    }
    gaussian.rcs = cloud.has_rcs ? FitRcsModel(directions, rcs, options) : RcsModel{};
  });
  RcsFitStats stats;
  stats.gaussians = n_gaussians;
  double rmse_sum = 0.0;
  for (const Gaussian& g : map.gaussians) {
    if (!g.rcs.valid()) {
      ++stats.no_model;
      continue;
    }
    ++stats.with_model;
    ++stats.degree_histogram[g.rcs.degree];
    stats.lowered_degree += g.rcs.degree < options.max_degree;
    rmse_sum += g.rcs.fit_rmse;
  }
  stats.mean_fit_rmse = stats.with_model ? rmse_sum / double(stats.with_model) : 0.0;
  SetMemberSpreads(member_spreads, stats);
  return stats;
}

}  // namespace radargauss
