// SPDX-License-Identifier: BSD-3-Clause
// The robust losses of residuals/loss.hpp evaluated: Ceres's loss classes,
// plus Geman-McClure, which Ceres 2.1 lacks, and their sum over the terms of
// one system or cost (the own solvers).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <ceres/loss_function.h>

#include "radargauss/residuals/loss.hpp"

namespace radargauss {

class GemanMcClureLoss final : public ceres::LossFunction {
 public:
  explicit GemanMcClureLoss(double a) : a2_(a * a) {}
  void Evaluate(double s, double rho[3]) const override {
    const double denominator = a2_ + s;
    rho[0] = a2_ * s / denominator;
    rho[1] = a2_ * a2_ / (denominator * denominator);
    rho[2] = -2.0 * rho[1] / denominator;
  }

 private:
  const double a2_;
};

// Dynamic covariance scaling as an M-estimator (residuals/loss.hpp): quadratic
// up to Phi = a^2, then rho' = 4 Phi^2 / (s + Phi)^2.
class DcsLoss final : public ceres::LossFunction {
 public:
  explicit DcsLoss(double a) : phi_(a * a) {}
  void Evaluate(double s, double rho[3]) const override {
    if (s <= phi_) {
      rho[0] = s;
      rho[1] = 1.0;
      rho[2] = 0.0;
      return;
    }
    const double scale = 2.0 * phi_ / (s + phi_);  // DCS's, in (0, 1)
    rho[0] = phi_ * (3.0 - 2.0 * scale);           // Phi (3 s - Phi) / (s + Phi), without overflow
    rho[1] = scale * scale;
    rho[2] = -rho[1] * scale / phi_;  // -2 rho' / (s + Phi)
  }

 private:
  const double phi_;
};

// A new loss (nullptr for trivial: Ceres's convention); the caller owns it.
ceres::LossFunction* MakeLoss(const LossConfig& config);

// A robust loss summed over the terms of one system or cost by the own
// solvers: Add(s) adds rho(s) to the sum and returns rho'(s), the IRLS weight
// (and rho''(s) when asked); Sum() is the sum of rho(s) so far. Ceres's loss
// classes evaluate every loss but Cauchy. Cauchy's rho costs a log per term,
// a large part of a tracking match, so it is summed here as one log of
// a product, sum a^2 log(x_i) = a^2 log(prod x_i) with x = 1 + s/a^2, and its
// derivatives are Ceres's closed forms: rho' = 1/x, rho'' = -1/(a^2 x^2).
class LossSum {
 public:
  explicit LossSum(const LossConfig& config);

  double Add(double s, double* second = nullptr) {
    if (cauchy_) {
      const double x = 1.0 + s * inverse_a2_;
      const double inverse = 1.0 / x;
      if (second) *second = -inverse_a2_ * (inverse * inverse);
      // product_ stays below 2^500 and a factor below 2^500 joins it, so it
      // never overflows; larger factors (and inf, NaN) take their own log.
      if (x < kRenormaliseAbove) {
        product_ *= x;
        if (product_ >= kRenormaliseAbove) Renormalise();
      } else {
        logs_ += std::log(x);
      }
      return std::max(std::numeric_limits<double>::min(), inverse);  // as Ceres
    }
    if (!loss_) {  // trivial
      sum_ += s;
      if (second) *second = 0.0;
      return 1.0;
    }
    double rho[3];
    loss_->Evaluate(s, rho);
    sum_ += rho[0];
    if (second) *second = rho[2];
    return rho[1];
  }

  double Sum() const;

 private:
  static constexpr double kRenormaliseAbove = 0x1p500;
  void Renormalise();

  std::unique_ptr<ceres::LossFunction> loss_;  // null for trivial and Cauchy
  bool cauchy_ = false;
  double a2_ = 1.0, inverse_a2_ = 1.0;
  double sum_ = 0.0;      // sum of rho (Ceres's losses)
  double product_ = 1.0;  // Cauchy: prod x = product_ 2^exponent_ exp(logs_)
  int exponent_ = 0;
  double logs_ = 0.0;
};

}  // namespace radargauss
