// SPDX-License-Identifier: BSD-3-Clause
// Per-Gaussian RCS models (paper section III-A, docs/design/map.md, "RCS models").
//
// Normalisation: m = median of the members' RCS (mean of the two middle
// values for an even count), s = min(m - min, max - m); members with
// |rcs - m| > s are outliers, the others map to y = (rcs - m) / s in [-1, 1].
// s = 0 (all equal, or one side of the median empty) means no model.
// Fit: c solves A c = y, A_ij = Y_j(d_i), in the least-squares sense by a
// complete orthogonal decomposition with a relative rank threshold: the
// minimum-norm solution, ill-determined directions truncated. When the
// inliers are too few (fewer than (L+1)^2) or A's numerical rank is below
// half of (L+1)^2 for degree L, the degree is lowered (adaptive) or the
// Gaussian gets no model. A fit that explains less of its inliers' variance
// than min_explained is replaced by the constant model.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/core/options.hpp"

namespace radargauss {

struct RcsNormalisation {
  bool valid = false;
  double median = 0.0;
  double scale = 0.0;
};

RcsNormalisation NormaliseRcs(std::vector<double> rcs);

// The incidence vector of a point p_r for a Gaussian centred at mu_r, both in
// the radar frame, before normalising and facing: u = p_r - mu_r (offset) or
// u = -mu_r (view). Templated so that residuals can differentiate it.
template <typename T>
Eigen::Matrix<T, 3, 1> IncidenceVector(IncidenceModel model, const Eigen::Matrix<T, 3, 1>& point_radar,
                                       const Eigen::Matrix<T, 3, 1>& mean_radar) {
  return model == IncidenceModel::kOffset ? Eigen::Matrix<T, 3, 1>(point_radar - mean_radar)
                                          : Eigen::Matrix<T, 3, 1>(-mean_radar);
}

// The sign s that makes s u face the radar ((s u).x <= 0): the incidence
// direction is d = s u / |u| (docs/design/map.md, "RCS models").
inline double FacingSign(const Eigen::Vector3d& u) { return u.x() > 0.0 ? -1.0 : 1.0; }

struct RcsFitOptions {
  int max_degree = kMaxShDegree;
  bool adaptive = true;
  IncidenceModel incidence = IncidenceModel::kOffset;
  // Relative pivot threshold of the decomposition: pivots below 1% of the
  // largest count as rank loss and their directions are truncated, instead of
  // fitting huge coefficients that explode off the sampled directions.
  double rank_threshold = 1e-2;
  // A fit whose view explains less than this share of its inliers' RCS
  // variance (RcsModel::explained) gets the constant model (degree 0).
  double min_explained = 0.0;
};
// Its options (options.hpp).
const OptionTable<RcsFitOptions>& RcsFitOptionTable();

// Sets a fit's spread_db and explained (RcsModel) from its inliers'
// squared residual and their squared deviation from their mean, both
// normalised, for `coefficients` fitted coefficients.
void SetRcsFitSpread(RcsModel& model, double residual_sq, double total_sq, std::size_t inliers, int coefficients);

// The adaptive degree, shared by the fit from the members (FitRcsModel) and
// the one from their statistics (RcsStatistics::Solve): from max_degree
// down, each degree the `inliers` determine is fitted by fit_at, which fills
// `model` and says whether its decomposition kept enough directions (always,
// without `adaptive`); a fit that explains less than min_explained gives
// way to the constant model. Degree -1: no fit.
RcsModel FitAdaptiveDegree(RcsModel model, std::size_t inliers, const RcsFitOptions& options,
                           const std::function<bool(int degree, RcsModel& model)>& fit_at);

// Fits one model from the members' incidence directions and raw RCS.
RcsModel FitRcsModel(const std::vector<Eigen::Vector3d>& directions, const std::vector<double>& rcs,
                     const RcsFitOptions& options = {});

struct RcsFitStats {
  std::size_t gaussians = 0;
  std::size_t with_model = 0;
  std::size_t lowered_degree = 0;  // has a model below max_degree
  std::size_t no_model = 0;
  std::array<std::size_t, kMaxShDegree + 1> degree_histogram{};
  double mean_fit_rmse = 0.0;  // over the Gaussians with a model
  // How a target's RCS varies across frames: the median over the Gaussians
  // of at least kSpreadMinMembers members of their members' RCS std (dB,
  // every member), binned by the members' mean range and mean |azimuth|
  // (docs/design/map.md, "RCS statistics"); -1 for an empty bin.
  static constexpr std::size_t kSpreadMinMembers = 4;
  static constexpr std::array<double, 4> kRangeBins{0.0, 20.0, 40.0, 70.0};  // m, lower edges
  static constexpr std::array<double, 3> kAzimuthBins{0.0, 15.0, 30.0};      // deg, lower edges
  std::array<double, 4> member_spread_by_range{-1.0, -1.0, -1.0, -1.0};
  std::array<double, 3> member_spread_by_azimuth{-1.0, -1.0, -1.0};
  double member_spread = -1.0;  // over all bins
};

// Fits the RCS model of every Gaussian of `map` from the cloud points
// associated to it (`association[i]` = Gaussian of point i or -1); sets
// map.incidence. Parallel over Gaussians; the same for any thread count.
RcsFitStats FitRcsModels(GaussianMap& map, const MapCloud& cloud, const std::vector<int>& association,
                         const RcsFitOptions& options = {});

}  // namespace radargauss
