#include "residuals/loss.hpp"

#include <stdexcept>

namespace radargauss {

LossType LossTypeFromString(const std::string& name) {
  if (name == "trivial" || name == "none") return LossType::kTrivial;
  if (name == "huber") return LossType::kHuber;
  if (name == "cauchy") return LossType::kCauchy;
  if (name == "geman-mcclure") return LossType::kGemanMcClure;
  if (name == "tukey") return LossType::kTukey;
  throw std::invalid_argument("unknown loss '" + name +
                              "' (trivial, huber, cauchy, geman-mcclure, tukey)");
}

std::string ToString(LossType type) {
  switch (type) {
    case LossType::kTrivial: return "trivial";
    case LossType::kHuber: return "huber";
    case LossType::kCauchy: return "cauchy";
    case LossType::kGemanMcClure: return "geman-mcclure";
    case LossType::kTukey: return "tukey";
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
