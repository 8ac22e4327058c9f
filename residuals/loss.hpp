// Robust losses for scan matching, from Ceres's loss classes (plus
// Geman-McClure, which Ceres 2.1 lacks), with a scale a, in Ceres's
// convention rho(s) of the squared residual s:
//   trivial        s
//   huber          s <= a^2 ? s : 2 a sqrt(s) - a^2
//   cauchy         a^2 log(1 + s / a^2)
//   geman-mcclure  a^2 s / (a^2 + s)
//   tukey          a^2/3 (1 - (1 - s/a^2)^3) for s <= a^2, else a^2/3
#pragma once

#include <memory>
#include <string>

#include <ceres/loss_function.h>

namespace radargauss {

enum class LossType { kTrivial, kHuber, kCauchy, kGemanMcClure, kTukey };

struct LossConfig {
  LossType type = LossType::kTrivial;
  double scale = 1.0;  // a
};

LossType LossTypeFromString(const std::string& name);  // throws std::invalid_argument
std::string ToString(LossType type);

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

// A new loss (nullptr for trivial: Ceres's convention); the caller owns it.
ceres::LossFunction* MakeLoss(const LossConfig& config);

// A loss owned for evaluation by the own solvers: rho(s), rho'(s) (the IRLS
// weight) and, when asked, rho''(s).
class RobustLoss {
 public:
  explicit RobustLoss(const LossConfig& config) : loss_(MakeLoss(config)) {}
  void Evaluate(double s, double& rho, double& weight, double* second = nullptr) const {
    if (!loss_) {
      rho = s;
      weight = 1.0;
      if (second) *second = 0.0;
      return;
    }
    double values[3];
    loss_->Evaluate(s, values);
    rho = values[0];
    weight = values[1];
    if (second) *second = values[2];
  }

 private:
  std::unique_ptr<ceres::LossFunction> loss_;
};

}  // namespace radargauss
