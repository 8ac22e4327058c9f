// SPDX-License-Identifier: BSD-3-Clause
// The RCS residual of scan matching (paper section III-B, docs/design/residuals.md,
// "Residuals"), for a radar point p_r whose normalised RCS y (with the associated
// Gaussian's median and scale) lies in [-1, 1]:
//
//   r_rcs = y - c . Y(d),   d = s u / |u|,   u = IncidenceVector(model, p_r, mu_r),
//   mu_r  = R^T (mu - t)    (the Gaussian centre in the radar frame),
//
// with the Gaussian's SH coefficients c up to its degree (runtime), and the
// facing sign s (d.x <= 0) taken at the pose of the association and held,
// like the associated Gaussian, until the next association: the paper's flip
// of d at u.x = 0 would make eq. 2 jump (odd SH bands) wherever a point
// crosses its Gaussian's y-z plane, and solvers need a smooth cost. Forms:
//   RcsResidual             rotation and translation blocks ("full");
//   RcsRotationResidual     the rotation block only, the translation a constant
//                           of the current association (the paper's choice);
//   RcsCoefficientResidual  either of these plus the Gaussian's coefficients
//                           as a block (joint refinement).
// Each has an analytic twin (ceres::CostFunction) sharing LineariseRcs.
// Every form takes the term's likelihood (rcs_likelihood.hpp) and weight:
//   r = w_c g_k(a r_rcs + b),  g_0 the identity (the paper's residual),
// with w_c the square root of the Gaussian's confidence.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>
#include <ceres/dynamic_autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/residuals/rcs_likelihood.hpp"
#include "radargauss/core/sh.hpp"
#include "radargauss/residuals/quaternion_jacobians.hpp"

namespace radargauss {

// What an RCS residual needs to know of its point and Gaussian.
struct RcsTerm {
  Eigen::Vector3d point_radar;  // p_r
  Eigen::Vector3d mean;         // mu, world frame
  double measurement = 0.0;     // y, normalised RCS in [-1, 1]
  int degree = 0;
  std::array<double, ShCoefficientCount(kMaxShDegree)> coefficients{};
  IncidenceModel incidence = IncidenceModel::kOffset;
  double facing = 1.0;         // s: FacingSign(u) at the association's pose
  std::uint32_t gaussian = 0;  // index in the map (for joint refinement)
  // The likelihood (rcs_likelihood.hpp): Gamma shape k (0: decibel) and
  // z = log_scale r_rcs + log_offset; the residual's weight w_c.
  double shape = 0.0;
  double log_scale = 1.0;
  double log_offset = 0.0;
  double weight = 1.0;
};

// The term's residual from the decibel one: w_c g_k(a r + b) (the identity
// times w_c for the decibel likelihood).
template <typename T>
T RcsLikelihoodResidual(const RcsTerm& term, const T& decibel) {
  if (term.shape == 0.0) return term.weight * decibel;
  return term.weight * SwerlingResidual(term.shape, T(term.log_scale * decibel + term.log_offset));
}

// d/d(decibel residual) of RcsLikelihoodResidual at `decibel`.
inline double RcsLikelihoodChain(const RcsTerm& term, double decibel) {
  if (term.shape == 0.0) return term.weight;
  return term.weight * term.log_scale *
         SwerlingResidualDerivative(term.shape, term.log_scale * decibel + term.log_offset);
}

// d = s u / |u| for the Gaussian centre mu_r in the radar frame; writes |u|.
template <typename T>
Eigen::Matrix<T, 3, 1> RcsDirection(const RcsTerm& term, const Eigen::Matrix<T, 3, 1>& mean_radar, T& norm) {
  const Eigen::Matrix<T, 3, 1> u = IncidenceVector<T>(term.incidence, term.point_radar.cast<T>(), mean_radar);
  using std::sqrt;
  norm = sqrt(u.squaredNorm());
  return T(term.facing) * u / norm;
}

// y - c . Y(d) for the Gaussian centre mu_r in the radar frame and
// coefficients c (the term's own, or a parameter block in joint refinement).
template <typename T, typename CoefficientT>
T RcsResidualAt(const RcsTerm& term, const Eigen::Matrix<T, 3, 1>& mean_radar, const CoefficientT* coefficients) {
  T norm = T(0.0);
  return RcsLikelihoodResidual<T>(
      term, T(term.measurement) - EvaluateSh<T>(term.degree, coefficients, RcsDirection<T>(term, mean_radar, norm)));
}

// The same for a rotation quaternion and a translation: mu_r = R^T (mu - t).
template <typename T, typename CoefficientT>
T RcsResidualValue(const RcsTerm& term, const T* rotation, const Eigen::Matrix<T, 3, 1>& translation,
                   const CoefficientT* coefficients) {
  const Eigen::Map<const Eigen::Quaternion<T>> q(rotation);
  return RcsResidualAt<T>(term, Eigen::Matrix<T, 3, 1>(q.conjugate() * (term.mean.cast<T>() - translation)),
                          coefficients);
}

template <typename T>
T RcsResidualValue(const RcsTerm& term, const T* rotation, const Eigen::Matrix<T, 3, 1>& translation) {
  return RcsResidualValue<T>(term, rotation, translation, term.coefficients.data());
}

class RcsResidual {
 public:
  explicit RcsResidual(const RcsTerm& term) : term_(term) {}

  template <typename T>
  bool operator()(const T* rotation, const T* translation, T* residual) const {
    residual[0] = RcsResidualValue<T>(term_, rotation, Eigen::Map<const Eigen::Matrix<T, 3, 1>>(translation));
    return true;
  }

  // Re-targets the residual at another term (problems kept across associations).
  void Reset(const RcsTerm& term) { term_ = term; }

  using AutoDiff = ceres::AutoDiffCostFunction<RcsResidual, 1, 4, 3>;
  static ceres::CostFunction* Create(const RcsTerm& term);                   // src/residuals/autodiff_costs.cpp
  static ceres::CostFunction* Create(std::unique_ptr<RcsResidual> functor);  // kept by the caller for Reset

 private:
  RcsTerm term_;
};

class RcsRotationResidual {
 public:
  RcsRotationResidual(const RcsTerm& term, const Eigen::Vector3d& translation)
      : term_(term), translation_(translation) {}

  template <typename T>
  bool operator()(const T* rotation, T* residual) const {
    residual[0] = RcsResidualValue<T>(term_, rotation, translation_.cast<T>());
    return true;
  }

  void Reset(const RcsTerm& term, const Eigen::Vector3d& translation) {
    term_ = term;
    translation_ = translation;
  }

  using AutoDiff = ceres::AutoDiffCostFunction<RcsRotationResidual, 1, 4>;
  static ceres::CostFunction* Create(const RcsTerm& term, const Eigen::Vector3d& translation);
  static ceres::CostFunction* Create(std::unique_ptr<RcsRotationResidual> functor);

 private:
  RcsTerm term_;
  Eigen::Vector3d translation_;
};

// Analytic linearisation shared by the analytic twins and the own GN: the
// residual and its derivative with respect to u (the un-normalised incidence
// vector), given the Gaussian centre in the radar frame mu_r = R^T (mu - t).
// With d = s u / |u| (s the term's facing sign):
//   dr/du = -(c^T dY/dd) s (I - d d^T) / |u|,
//   u = p_r - mu_r (offset) or -mu_r (view), so du/dq = -d(R^T a)/dq and
//   du/dt = R^T, with a = mu - t.
// The likelihood's chain factor dr/dr_rcs (RcsLikelihoodChain) multiplies
// dr/du, and dr/dc = -chain Y(d).
struct RcsLinearisation {
  double residual = 0.0;
  Eigen::RowVector3d dr_du = Eigen::RowVector3d::Zero();
  double chain = 1.0;
};

// With coefficients c from a parameter block (joint refinement), else the
// term's; writes Y(d) to `basis_out` when given (dr/dc = -chain Y(d)).
inline RcsLinearisation LineariseRcs(const RcsTerm& term, const Eigen::Vector3d& mean_radar, const double* coefficients,
                                     double* basis_out = nullptr) {
  double norm = 0.0;
  RcsLinearisation out;
  const Eigen::Vector3d d = RcsDirection<double>(term, mean_radar, norm);
  Eigen::Vector3d c_dY;
  const double prediction = EvaluateShWithGradient(term.degree, coefficients, d, c_dY, basis_out);
  const double decibel = term.measurement - prediction;
  out.residual = RcsLikelihoodResidual(term, decibel);
  out.chain = RcsLikelihoodChain(term, decibel);
  out.dr_du = -(out.chain * term.facing / norm) * (c_dY - c_dY.dot(d) * d).transpose();  // c_dY^T (I - d d^T)
  return out;
}

inline RcsLinearisation LineariseRcs(const RcsTerm& term, const Eigen::Vector3d& mean_radar) {
  return LineariseRcs(term, mean_radar, term.coefficients.data());
}

// The evaluation every analytic RCS twin shares: r at the pose (rotation,
// t) with coefficients c; with `with_jacobians`, through LineariseRcs, and
// where asked dr/dq (1x4), dr/dc (1x(degree+1)^2) and dr/dt (1x3).
inline bool EvaluateRcsTerm(const RcsTerm& term, const double* rotation, const Eigen::Vector3d& t,
                            const double* coefficients, double* residual, bool with_jacobians,
                            double* rotation_jacobian, double* coefficient_jacobian, double* translation_jacobian) {
  if (!with_jacobians) {  // the cost alone (Ceres's step evaluations)
    residual[0] = RcsResidualValue<double>(term, rotation, t, coefficients);
    return true;
  }
  const Eigen::Map<const Eigen::Quaterniond> q(rotation);
  // coefficient_jacobian, when asked for, receives Y(d); dr/dc = -chain Y(d).
  const RcsLinearisation lin = LineariseRcs(term, q.conjugate() * (term.mean - t), coefficients, coefficient_jacobian);
  residual[0] = lin.residual;
  if (rotation_jacobian != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 1, 4>> J(rotation_jacobian);
    J = InverseRotatePointJacobianLeft(-lin.dr_du, rotation, term.mean - t);
  }
  if (coefficient_jacobian != nullptr) {
    for (int i = 0; i < ShCoefficientCount(term.degree); ++i) coefficient_jacobian[i] *= -lin.chain;
  }
  if (translation_jacobian != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 1, 3>> J(translation_jacobian);
    J = (q * lin.dr_du.transpose()).transpose();  // dr/du R^T
  }
  return true;
}

// The analytic twin of RcsResidual ("full": rotation and translation).
class RcsCostFunction final : public ceres::SizedCostFunction<1, 4, 3> {
 public:
  explicit RcsCostFunction(const RcsTerm& term) : term_(term) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    return EvaluateRcsTerm(term_, parameters[0], Eigen::Map<const Eigen::Vector3d>(parameters[1]),
                           term_.coefficients.data(), residuals, jacobians != nullptr,
                           jacobians ? jacobians[0] : nullptr, nullptr, jacobians ? jacobians[1] : nullptr);
  }

  void Reset(const RcsTerm& term) { term_ = term; }

 private:
  RcsTerm term_;
};

// The analytic twin of RcsRotationResidual.
class RcsRotationCostFunction final : public ceres::SizedCostFunction<1, 4> {
 public:
  RcsRotationCostFunction(const RcsTerm& term, const Eigen::Vector3d& translation)
      : term_(term), translation_(translation) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    return EvaluateRcsTerm(term_, parameters[0], translation_, term_.coefficients.data(), residuals,
                           jacobians != nullptr, jacobians ? jacobians[0] : nullptr, nullptr, nullptr);
  }

  void Reset(const RcsTerm& term, const Eigen::Vector3d& translation) {
    term_ = term;
    translation_ = translation;
  }

 private:
  RcsTerm term_;
  Eigen::Vector3d translation_;
};

// Joint refinement (docs/design/solvers.md, "Joint refinement"): the same residual with the
// Gaussian's coefficients c as a parameter block, so that scans tie their
// poses to the map. Blocks: rotation (4), coefficients ((degree + 1)^2) and,
// with `full`, translation (3); rotation-only takes the translation as a
// constant of the association. dr/dc = -Y(d).
class RcsCoefficientResidual {
 public:
  RcsCoefficientResidual(const RcsTerm& term, const Eigen::Vector3d& translation, bool full)
      : term_(term), translation_(translation), full_(full) {}

  template <typename T>
  bool operator()(T const* const* parameters, T* residual) const {
    const Eigen::Matrix<T, 3, 1> t = full_
                                         ? Eigen::Matrix<T, 3, 1>(parameters[2][0], parameters[2][1], parameters[2][2])
                                         : Eigen::Matrix<T, 3, 1>(translation_.cast<T>());
    residual[0] = RcsResidualValue<T, T>(term_, parameters[0], t, parameters[1]);
    return true;
  }

  using AutoDiff = ceres::DynamicAutoDiffCostFunction<RcsCoefficientResidual, 4>;
  static ceres::CostFunction* Create(const RcsTerm& term, const Eigen::Vector3d& translation, bool full);

 private:
  const RcsTerm term_;
  const Eigen::Vector3d translation_;
  const bool full_;
};

// The analytic twin of RcsCoefficientResidual (same blocks).
class RcsCoefficientCostFunction final : public ceres::CostFunction {
 public:
  RcsCoefficientCostFunction(const RcsTerm& term, const Eigen::Vector3d& translation, bool full)
      : term_(term), translation_(translation), full_(full) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->push_back(4);
    mutable_parameter_block_sizes()->push_back(ShCoefficientCount(term.degree));
    if (full) mutable_parameter_block_sizes()->push_back(3);
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Eigen::Vector3d t =
        full_ ? Eigen::Vector3d(parameters[2][0], parameters[2][1], parameters[2][2]) : translation_;
    return EvaluateRcsTerm(term_, parameters[0], t, parameters[1], residuals, jacobians != nullptr,
                           jacobians ? jacobians[0] : nullptr, jacobians ? jacobians[1] : nullptr,
                           full_ && jacobians ? jacobians[2] : nullptr);
  }

 private:
  const RcsTerm term_;
  const Eigen::Vector3d translation_;
  const bool full_;
};

}  // namespace radargauss
