// SPDX-License-Identifier: BSD-3-Clause
// Robust losses for scan matching by name and scale a, in Ceres's
// convention rho(s) of the squared residual s (their evaluation, from
// Ceres's loss classes, is residuals/robust_loss.hpp):
//   trivial        s
//   huber          s <= a^2 ? s : 2 a sqrt(s) - a^2
//   cauchy         a^2 log(1 + s / a^2)
//   geman-mcclure  a^2 s / (a^2 + s)
//   tukey          a^2/3 (1 - (1 - s/a^2)^3) for s <= a^2, else a^2/3
//   dcs            s for s <= a^2, else a^2 (3 s - a^2) / (s + a^2): dynamic
//                  covariance scaling (Agarwal et al. 2013, Phi = a^2), whose
//                  rho' is the square of its scale min(1, 2 Phi / (Phi + s))
#pragma once

#include <string>
#include <vector>

namespace radargauss {

enum class LossType { kTrivial, kHuber, kCauchy, kGemanMcClure, kTukey, kDcs };

struct LossConfig {
  LossType type = LossType::kTrivial;
  double scale = 1.0;  // a
};

LossType LossTypeFromString(const std::string& name);  // throws std::invalid_argument ("none": trivial)
std::string ToString(LossType type);
const std::vector<std::string>& LossNames();  // every loss's name, in enum order

}  // namespace radargauss
