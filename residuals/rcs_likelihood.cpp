// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/residuals/rcs_likelihood.hpp"

#include <algorithm>

#include "radargauss/names.hpp"
#include "radargauss/sh.hpp"

namespace radargauss {

namespace {

const NamedValue<RcsLikelihood> kRcsLikelihoodNames[] = {
    {RcsLikelihood::kDecibel, "decibel"},
    {RcsLikelihood::kSwerling1, "swerling1"},
    {RcsLikelihood::kSwerling3, "swerling3"},
};

constexpr double kPi = 3.14159265358979323846;
constexpr double kDbPerNeper = 4.342944819032518;  // 10 / ln(10)

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
      return kDbPerNeper * std::sqrt(kPi * kPi / 6.0);
    case RcsLikelihood::kSwerling3:
      return kDbPerNeper * std::sqrt(kPi * kPi / 6.0 - 1.0);
    case RcsLikelihood::kDecibel:
      break;
  }
  return 2.0;
}

double RcsConfidence(double spread_db, int degree, unsigned inliers, double expected_spread_db) {
  if (degree < 0 || inliers == 0) return 0.0;
  const double p = double(ShCoefficientCount(degree));
  const double predictive = spread_db * spread_db * (1.0 + p / double(inliers));
  const double expected = expected_spread_db * expected_spread_db;
  return predictive <= expected ? 1.0 : expected / predictive;
}

}  // namespace radargauss
