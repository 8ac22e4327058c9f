// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/residuals/robust_loss.hpp"

#include "radargauss/core/names.hpp"

#include <stdexcept>
#include <utility>

namespace radargauss {

namespace {

const NamedValue<LossType> kLossNames[] = {
    {LossType::kTrivial, "trivial"}, {LossType::kHuber, "huber"},
    {LossType::kCauchy, "cauchy"},   {LossType::kGemanMcClure, "geman-mcclure"},
    {LossType::kTukey, "tukey"},     {LossType::kDcs, "dcs"},
};

}  // namespace

const std::vector<std::string>& LossNames() {
  static const std::vector<std::string> names = NamesOf(kLossNames);
  return names;
}

LossType LossTypeFromString(const std::string& name) {
  return name == "none" ? LossType::kTrivial : ValueNamed(kLossNames, name, "loss");
}

std::string ToString(LossType type) { return NameOf(kLossNames, type); }

namespace {

void ValidateScale(const LossConfig& config) {
  if (!(config.scale > 0.0)) throw std::invalid_argument("loss scale must be > 0");
}

}  // namespace

ceres::LossFunction* MakeLoss(const LossConfig& config) {
  ValidateScale(config);
  switch (config.type) {
    case LossType::kTrivial:
      return nullptr;
    case LossType::kHuber:
      return new ceres::HuberLoss(config.scale);
    case LossType::kCauchy:
      return new ceres::CauchyLoss(config.scale);
    case LossType::kGemanMcClure:
      return new GemanMcClureLoss(config.scale);
    case LossType::kTukey:
      return new ceres::TukeyLoss(config.scale);
    case LossType::kDcs:
      return new DcsLoss(config.scale);
  }
  return nullptr;
}

LossSum::LossSum(const LossConfig& config) {
  if (config.type == LossType::kCauchy) {
    ValidateScale(config);
    cauchy_ = true;
    a2_ = config.scale * config.scale;
    inverse_a2_ = 1.0 / a2_;
  } else {
    loss_.reset(MakeLoss(config));
  }
}

void LossSum::Renormalise() {
  int exponent = 0;
  product_ = std::frexp(product_, &exponent);
  exponent_ += exponent;
}

double LossSum::Sum() const {
  if (!cauchy_) return sum_;
  return a2_ * (std::log(product_) + exponent_ * std::log(2.0) + logs_);
}

}  // namespace radargauss
