// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/residuals/loss.hpp"

#include <stdexcept>
#include <utility>

namespace radargauss {

namespace {

// Every loss's name, in enum order: the one table the parsers and lists use.
const std::pair<LossType, const char*> kLossNames[] = {
    {LossType::kTrivial, "trivial"},
    {LossType::kHuber, "huber"},
    {LossType::kCauchy, "cauchy"},
    {LossType::kGemanMcClure, "geman-mcclure"},
    {LossType::kTukey, "tukey"},
};

}  // namespace

const std::vector<std::string>& LossNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all;
    for (const auto& entry : kLossNames) all.push_back(entry.second);
    return all;
  }();
  return names;
}

LossType LossTypeFromString(const std::string& name) {
  if (name == "none") return LossType::kTrivial;
  for (const auto& [type, n] : kLossNames) {
    if (name == n) return type;
  }
  std::string known;
  for (const std::string& n : LossNames()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown loss '" + name + "' (" + known + ")");
}

std::string ToString(LossType type) {
  for (const auto& [t, name] : kLossNames) {
    if (t == type) return name;
  }
  return "unknown";
}

namespace {

void ValidateScale(const LossConfig& config) {
  if (!(config.scale > 0.0)) throw std::invalid_argument("loss scale must be > 0");
}

}  // namespace

ceres::LossFunction* MakeLoss(const LossConfig& config) {
  ValidateScale(config);
  switch (config.type) {
    case LossType::kTrivial: return nullptr;
    case LossType::kHuber: return new ceres::HuberLoss(config.scale);
    case LossType::kCauchy: return new ceres::CauchyLoss(config.scale);
    case LossType::kGemanMcClure: return new GemanMcClureLoss(config.scale);
    case LossType::kTukey: return new ceres::TukeyLoss(config.scale);
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
