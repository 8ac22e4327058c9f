// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/residuals/rcs_likelihood.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "radargauss/core/names.hpp"
#include "radargauss/core/sh.hpp"
#include "radargauss/core/stats.hpp"

namespace radargauss {

namespace {

const NamedValue<RcsLikelihood> kRcsLikelihoodNames[] = {
    {RcsLikelihood::kDecibel, "decibel"},
    {RcsLikelihood::kSwerling1, "swerling1"},
    {RcsLikelihood::kSwerling3, "swerling3"},
};

constexpr double kPi = 3.14159265358979323846;

}  // namespace

const std::vector<std::string>& RcsLikelihoodNames() {
  static const std::vector<std::string> names = NamesOf(kRcsLikelihoodNames);
  return names;
}

RcsLikelihood RcsLikelihoodFromString(const std::string& name) {
  return ValueNamed(kRcsLikelihoodNames, name, "RCS likelihood");
}

std::string ToString(RcsLikelihood likelihood) { return NameOf(kRcsLikelihoodNames, likelihood); }

double RcsLikelihoodSpreadDb(RcsLikelihood likelihood) {
  // The variance of ln X for X ~ Gamma(k, 1/k) is the trigamma psi_1(k):
  // pi^2 / 6 for k = 1, pi^2 / 6 - 1 for k = 2.
  switch (likelihood) {
    case RcsLikelihood::kSwerling1:
      return std::sqrt(kPi * kPi / 6.0) / kNepersPerDecibel;
    case RcsLikelihood::kSwerling3:
      return std::sqrt(kPi * kPi / 6.0 - 1.0) / kNepersPerDecibel;
    case RcsLikelihood::kDecibel:
      break;
  }
  return 2.0;
}

double ExpectedSpreadDb(const RcsTermOptions& options) {
  return options.expected_spread_db > 0.0 ? options.expected_spread_db : RcsLikelihoodSpreadDb(options.likelihood);
}

double RcsConfidence(double spread_db, int degree, unsigned inliers, double expected_spread_db) {
  if (degree < 0 || inliers == 0) return 0.0;
  const double p = double(ShCoefficientCount(degree));
  const double predictive = spread_db * spread_db * (1.0 + p / double(inliers));
  const double expected = expected_spread_db * expected_spread_db;
  return predictive <= expected ? 1.0 : expected / predictive;
}

RcsMapSummary SummariseRcs(const GaussianMap& map, const RcsTermOptions& options) {
  if (!(options.expected_spread_db >= 0.0) || !std::isfinite(options.expected_spread_db)) {
    throw std::invalid_argument("expected_spread must be a finite number >= 0 (dB), not " +
                                std::to_string(options.expected_spread_db));
  }
  const double expected = ExpectedSpreadDb(options);
  RcsMapSummary summary;
  std::vector<double> spreads, explained;
  double confidence_sum = 0.0, information_sum = 0.0;
  for (const Gaussian& g : map.gaussians) {
    if (!g.rcs.valid()) continue;
    spreads.push_back(g.rcs.spread_db);
    explained.push_back(g.rcs.explained);
    const double confidence = RcsConfidence(g.rcs.spread_db, g.rcs.degree, g.rcs.inliers, expected);
    confidence_sum += confidence;
    information_sum +=
        confidence * double(ShCoefficientCount(g.rcs.degree) - 1) / double(ShCoefficientCount(kMaxShDegree) - 1);
  }
  summary.models = spreads.size();
  if (summary.models == 0) return summary;
  summary.median_spread_db = Median(std::move(spreads));
  summary.median_explained = Median(std::move(explained));
  summary.mean_confidence = confidence_sum / double(summary.models);
  summary.view_information = information_sum / double(summary.models);
  return summary;
}

double RcsWeightFromMap(const RcsMapSummary& summary) {
  return std::min(kMaxChosenRcsWeight, kRcsWeightPerInformation * summary.view_information);
}

}  // namespace radargauss
