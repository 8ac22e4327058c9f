// SPDX-License-Identifier: BSD-3-Clause
// The likelihoods of the RCS term (docs/design/residuals.md, "RCS likelihoods") and
// the per-Gaussian confidence that weighs it ("RCS confidence").
//
// decibel     r = y - c . Y(d): the paper's residual in the Gaussian's
//             normalised dB (Gaussian noise in dB).
// swerling1   the linear RCS exponential about the model's mean (Swerling
//             I/II), shape k = 1;
// swerling3   chi-square with 4 degrees of freedom (Swerling III/IV), k = 2.
// For Gamma(k, mean / k) fluctuation, with z = ln(sigma / mean) the log of
// the measured linear RCS over the model's mean, the negative log-likelihood
// in the mean is k (e^z - z - 1) plus a constant, zero and smallest at
// z = 0; the residual r = sign(z) sqrt(2 k (e^z - z - 1)) has it as r^2 / 2,
// so a least-squares solver maximises the likelihood. From the decibel
// residual r_db: z = a r_db + b with a = scale ln(10) / 10 and
// b = -offset ln(10) / 10, offset the Gaussian's mean_offset_db.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "radargauss/map/gaussian_map.hpp"

namespace radargauss {

enum class RcsLikelihood { kDecibel, kSwerling1, kSwerling3 };

RcsLikelihood RcsLikelihoodFromString(const std::string& name);  // throws std::invalid_argument
std::string ToString(RcsLikelihood likelihood);
const std::vector<std::string>& RcsLikelihoodNames();  // in enum order

// The Gamma shape k of a Swerling likelihood; 0 for the decibel residual.
inline double SwerlingShape(RcsLikelihood likelihood) {
  return likelihood == RcsLikelihood::kSwerling1 ? 1.0 : likelihood == RcsLikelihood::kSwerling3 ? 2.0 : 0.0;
}

// How the RCS terms of a match are made (ScanMatchingOptions::rcs_terms).
struct RcsTermOptions {
  RcsLikelihood likelihood = RcsLikelihood::kDecibel;
  // Weigh each term by its Gaussian's confidence (RcsConfidence).
  bool confidence = false;
  // The spread (dB) a residual expects of its measurements; 0: the
  // likelihood's own (RcsLikelihoodSpreadDb).
  double expected_spread_db = 0.0;
};

// ln(10) / 10: nepers (natural-log units) per decibel.
inline constexpr double kNepersPerDecibel = 0.23025850929940458;

// The std (dB) of a measurement about its mean under the likelihood: for
// Gamma(k) fluctuation, 10 / ln(10) sqrt(psi_1(k)) (5.57 dB for k = 1, 3.49
// dB for k = 2); for the decibel residual, 2 dB.
double RcsLikelihoodSpreadDb(RcsLikelihood likelihood);

// The spread the confidence expects: options.expected_spread_db, or the
// likelihood's own when that is 0.
double ExpectedSpreadDb(const RcsTermOptions& options);

// A Gaussian's confidence in [0, 1]: the expected variance over the
// predictive variance of a new measurement about the fitted model,
// min(1, s_e^2 / (spread^2 (1 + p / n))), with p = (degree + 1)^2
// coefficients fitted from n inliers of residual spread `spread_db`.
double RcsConfidence(double spread_db, int degree, unsigned inliers, double expected_spread_db);

// sign(z) sqrt(2 k (e^z - z - 1)) for the Jets of autodiff and for
// doubles; below |z| = 1e-3 by its series sqrt(k) z sqrt(1 + z/3 + z^2/12),
// which has no cancellation at 0.
template <typename T>
T SwerlingResidual(double k, const T& z) {
  using std::abs;
  using std::exp;
  using std::sqrt;
  if (abs(z) < T(1e-3)) return sqrt(k) * z * sqrt(T(1.0) + z / 3.0 + z * z / 12.0);
  const T h = exp(z) - z - T(1.0);
  return z < T(0.0) ? -sqrt(2.0 * k * h) : sqrt(2.0 * k * h);
}

// d/dz of SwerlingResidual: k (e^z - 1) / r, and its series' derivative
// near 0 (sqrt(k) at z = 0).
inline double SwerlingResidualDerivative(double k, double z) {
  if (std::abs(z) < 1e-3) {
    const double q = 1.0 + z / 3.0 + z * z / 12.0;
    return std::sqrt(k) * (std::sqrt(q) + z * (1.0 / 3.0 + z / 6.0) / (2.0 * std::sqrt(q)));
  }
  return k * std::expm1(z) / SwerlingResidual(k, z);
}

// What a map's RCS models know, over the Gaussians with a model
// (docs/design/map.md, "The RCS weight from the map").
struct RcsMapSummary {
  std::size_t models = 0;
  double median_spread_db = 0.0;
  double median_explained = 0.0;
  double mean_confidence = 0.0;  // RcsConfidence with the likelihood's spread
  // The mean over the models of confidence x (p - 1) / 15, p = (L + 1)^2:
  // the view-dependent coefficients the members support, as a share of a
  // degree-3 model's, weighed by how far the fit can be trusted; in [0, 1].
  double view_information = 0.0;
};
RcsMapSummary SummariseRcs(const GaussianMap& map, const RcsTermOptions& options);

// The data-chosen w_rcs of eq. 2: kRcsWeightPerInformation times the map's
// view information, at most kMaxChosenRcsWeight (docs/design/map.md, "The RCS
// weight from the map").
inline constexpr double kRcsWeightPerInformation = 1.5;
inline constexpr double kMaxChosenRcsWeight = 0.75;
double RcsWeightFromMap(const RcsMapSummary& summary);

}  // namespace radargauss
