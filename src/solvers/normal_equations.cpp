// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/solvers/normal_equations.hpp"

#include <ceres/jet.h>

#include <algorithm>

#include "radargauss/core/conventions.hpp"
#include "radargauss/lie/manifold.hpp"
#include "radargauss/residuals/geometric_residual.hpp"
#include "radargauss/residuals/robust_loss.hpp"

namespace radargauss {

namespace {

using Matrix3x6 = Eigen::Matrix<double, 3, 6>;
using Jet7 = ceres::Jet<double, 7>;

// d q / d dphi at q (right perturbation): the SO3Manifold PlusJacobian.
Eigen::Matrix<double, 4, 3> QuaternionTangent(const SO3d& rotation) {
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> P;
  SO3Manifold().PlusJacobian(rotation.data(), P.data());
  return P;
}

// Jets seeded for the rotation (derivatives 0..3) and translation (4..6) blocks.
void SeedJets(const SE3d& pose, const Eigen::Vector3d& translation, Jet7 rotation[4], Jet7 t[3]) {
  for (int i = 0; i < 4; ++i) rotation[i] = Jet7(pose.rotation().data()[i], i);
  for (int i = 0; i < 3; ++i) t[i] = Jet7(translation[i], 4 + i);
}

// The loss's curvature along r (GaussNewtonOptions::loss_curvature): the
// coefficient c of (J^T r)(J^T r)^T, 2 rho'' clamped so that rho' + c s >= 0.
double CurvatureAlongResidual(double s, double weight, double second) {
  return s > 0.0 ? std::max(2.0 * second, -weight / s) : 0.0;
}

// Fixed sizes throughout: this is the inner loop of every iteration. J holds
// the columns of the tangent block starting at `offset` (all six, or the
// rotation's three).
template <int Rows, int Cols>
void Accumulate(LinearSystem& system, int offset, const Eigen::Matrix<double, Rows, Cols>& J,
                const Eigen::Matrix<double, Rows, 1>& r, LossSum& loss, bool loss_curvature) {
  double second = 0.0;
  const double s = r.squaredNorm();
  const double weight = loss.Add(s, &second);
  const Eigen::Matrix<double, Rows, Cols> weighted_J = weight * J;
  system.H.block<Cols, Cols>(offset, offset).noalias() += weighted_J.transpose() * J;
  system.g.segment<Cols>(offset).noalias() += weighted_J.transpose() * r;
  if (loss_curvature && second != 0.0) {
    const Eigen::Matrix<double, Cols, 1> Jt_r = J.transpose() * r;
    system.loss_curvature.block<Cols, Cols>(offset, offset).noalias() +=
        CurvatureAlongResidual(s, weight, second) * Jt_r * Jt_r.transpose();
  }
  ++system.residuals;
}

// The sums of BuildGeometricSystem's analytic path, taken without R (see
// there): with T = double one term at a time, with T = Eigen::Array2d two
// terms at once, one per SIMD lane (the same arithmetic in half the
// instructions; this loop was a third of a match's).
template <typename T>
struct GeometricSums {
  T A_tt[6], A_rr[6];  // symmetric: upper triangles (00 01 02 11 12 22)
  T A_tr[3][3];
  T b_t[3], b_r[3];
  explicit GeometricSums(const T& zero) {
    for (int i = 0; i < 6; ++i) A_tt[i] = A_rr[i] = zero;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) A_tr[i][j] = zero;
      b_t[i] = b_r[i] = zero;
    }
  }
};

// What a term brings: the upper triangle of L^T (00 01 02 11 12 22), q = R p
// and e = q + t - mu.
template <typename T>
struct GeometricTermInputs {
  T U[6], q[3], e[3];
};

// One value per lane: f(0) for a term, f(0) and f(1) for a pair.
template <typename T>
struct Lanes;
template <>
struct Lanes<double> {
  template <typename F>
  static double Of(F&& f) {
    return f(0);
  }
};
template <>
struct Lanes<Eigen::Array2d> {
  template <typename F>
  static Eigen::Array2d Of(F&& f) {
    return Eigen::Array2d(f(0), f(1));
  }
};

// The inputs of term k, and of term k + 1 in the second lane of a pair.
template <typename T>
GeometricTermInputs<T> Inputs(const Correspondences& c, std::size_t k, const Eigen::Matrix3d& R,
                              const Eigen::Vector3d& t) {
  const GeometricTerm* terms = &c.geometric[k];
  const auto gather = [&](auto&& value) { return Lanes<T>::Of([&](int lane) { return value(terms[lane]); }); };
  constexpr int kUpper[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
  GeometricTermInputs<T> in;
  for (int i = 0; i < 6; ++i) {
    in.U[i] = gather([&](const GeometricTerm& term) {
      return c.index->SqrtInformationT(term.gaussian)(kUpper[i][0], kUpper[i][1]);
    });
  }
  T p[3], mean[3];
  for (int i = 0; i < 3; ++i) {
    p[i] = gather([&](const GeometricTerm& term) { return term.point_radar[i]; });
    mean[i] = gather([&](const GeometricTerm& term) { return c.index->Mean(term.gaussian)[i]; });
  }
  for (int i = 0; i < 3; ++i) {
    in.q[i] = R(i, 0) * p[0] + R(i, 1) * p[1] + R(i, 2) * p[2];
    in.e[i] = in.q[i] + t[i] - mean[i];
  }
  return in;
}

// Adds a term (or a pair) to `sums`; weight_of(s, Sigma^-1 e) gives the IRLS
// weight of s = e^T Sigma^-1 e.
template <typename T, typename WeightOf>
void AddGeometricTerm(const GeometricTermInputs<T>& in, GeometricSums<T>& sums, WeightOf&& weight_of) {
  T information[6];
  InformationFromSqrtInformationT(in.U, information);
  const T &i00 = information[0], &i01 = information[1], &i02 = information[2];
  const T &i11 = information[3], &i12 = information[4], &i22 = information[5];
  const T* q = in.q;
  const T* e = in.e;
  const T information_e[3] = {i00 * e[0] + i01 * e[1] + i02 * e[2], i01 * e[0] + i11 * e[1] + i12 * e[2],
                              i02 * e[0] + i12 * e[1] + i22 * e[2]};
  const T weight =
      weight_of(e[0] * information_e[0] + e[1] * information_e[1] + e[2] * information_e[2], information_e);
  // B = w Sigma^-1 [q]x column by column (column k is Sigma^-1 (w q x e_k)),
  // then the upper triangle of [q]x B as components of cross products: the
  // zeros of [q]x never enter a product.
  const T wq[3] = {weight * q[0], weight * q[1], weight * q[2]};
  const T B[3][3] = {{wq[2] * i01 - wq[1] * i02, wq[0] * i02 - wq[2] * i00, wq[1] * i00 - wq[0] * i01},
                     {wq[2] * i11 - wq[1] * i12, wq[0] * i12 - wq[2] * i01, wq[1] * i01 - wq[0] * i11},
                     {wq[2] * i12 - wq[1] * i22, wq[0] * i22 - wq[2] * i02, wq[1] * i02 - wq[0] * i12}};
  sums.A_tt[0] += weight * i00;
  sums.A_tt[1] += weight * i01;
  sums.A_tt[2] += weight * i02;
  sums.A_tt[3] += weight * i11;
  sums.A_tt[4] += weight * i12;
  sums.A_tt[5] += weight * i22;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) sums.A_tr[i][j] -= B[i][j];
  }
  // (q x B_k)_i for i <= k; A_rr -= it ([q]x^T = -[q]x).
  sums.A_rr[0] -= q[1] * B[2][0] - q[2] * B[1][0];
  sums.A_rr[1] -= q[1] * B[2][1] - q[2] * B[1][1];
  sums.A_rr[2] -= q[1] * B[2][2] - q[2] * B[1][2];
  sums.A_rr[3] -= q[2] * B[0][1] - q[0] * B[2][1];
  sums.A_rr[4] -= q[2] * B[0][2] - q[0] * B[2][2];
  sums.A_rr[5] -= q[0] * B[1][2] - q[1] * B[0][2];
  for (int i = 0; i < 3; ++i) sums.b_t[i] += weight * information_e[i];
  sums.b_r[0] += wq[1] * information_e[2] - wq[2] * information_e[1];
  sums.b_r[1] += wq[2] * information_e[0] - wq[0] * information_e[2];
  sums.b_r[2] += wq[0] * information_e[1] - wq[1] * information_e[0];
}

// H and g from the sums taken without R (BuildGeometricSystem): the lanes
// added up, then H_tr = A_tr R, H_rr = R^T A_rr R, g_r = R^T b_r.
void AddRotatedSums(const GeometricSums<double>& single, const GeometricSums<Eigen::Array2d>& pairs,
                    const Eigen::Matrix3d& R, LinearSystem& system) {
  double A_tt_upper[6], A_rr_upper[6];
  Eigen::Matrix3d A_tr;
  Eigen::Vector3d b_t, b_r;
  for (int i = 0; i < 6; ++i) {
    A_tt_upper[i] = single.A_tt[i] + pairs.A_tt[i].sum();
    A_rr_upper[i] = single.A_rr[i] + pairs.A_rr[i].sum();
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) A_tr(i, j) = single.A_tr[i][j] + pairs.A_tr[i][j].sum();
    b_t[i] = single.b_t[i] + pairs.b_t[i].sum();
    b_r[i] = single.b_r[i] + pairs.b_r[i].sum();
  }
  const auto from_upper = [](const double* u) {
    Eigen::Matrix3d m;
    m << u[0], u[1], u[2], u[1], u[3], u[4], u[2], u[4], u[5];
    return m;
  };
  const Eigen::Matrix3d A_tt = from_upper(A_tt_upper), A_rr = from_upper(A_rr_upper);
  system.H.block<3, 3>(kTranslationOffset, kTranslationOffset) = A_tt;
  system.H.block<3, 3>(kTranslationOffset, kRotationOffset) = A_tr * R;
  system.H.block<3, 3>(kRotationOffset, kTranslationOffset) = (A_tr * R).transpose();
  system.H.block<3, 3>(kRotationOffset, kRotationOffset) = R.transpose() * A_rr * R;
  system.g.segment<3>(kTranslationOffset) = b_t;
  system.g.segment<3>(kRotationOffset) = R.transpose() * b_r;
}

// Autodiff: the Ceres functor evaluated with Jets, per term.
LinearSystem AutoDiffGeometricSystem(const Correspondences& c, const SE3d& pose, const ScanMatchingOptions& options,
                                     bool loss_curvature) {
  LinearSystem system;
  LossSum loss(options.geometric_loss);
  const Eigen::Matrix<double, 4, 3> P = QuaternionTangent(pose.rotation());
  for (const GeometricTerm& term : c.geometric) {
    const Eigen::Matrix3d& LT = c.index->SqrtInformationT(term.gaussian);
    const Eigen::Vector3d& mean = c.index->Mean(term.gaussian);
    Jet7 rotation[4], t[3], residual[3];
    SeedJets(pose, pose.translation(), rotation, t);
    const GeometricResidual functor(term.point_radar, mean, LT);
    functor(rotation, t, residual);
    Eigen::Vector3d r;
    Eigen::Matrix<double, 3, 7> ambient;
    for (int i = 0; i < 3; ++i) {
      r[i] = residual[i].a;
      ambient.row(i) = residual[i].v.transpose();
    }
    Matrix3x6 J;
    J.block<3, 3>(0, kTranslationOffset) = ambient.rightCols<3>();
    J.block<3, 3>(0, kRotationOffset) = ambient.leftCols<4>() * P;
    Accumulate(system, 0, J, r, loss, loss_curvature);
  }
  system.rho_sum = loss.Sum();
  return system;
}

}  // namespace

LinearSystem BuildGeometricSystem(const Correspondences& c, const SE3d& pose, const ScanMatchingOptions& options,
                                  bool loss_curvature) {
  if (options.jacobians == JacobianMode::kAutoDiff) return AutoDiffGeometricSystem(c, pose, options, loss_curvature);
  LinearSystem system;
  LossSum loss(options.geometric_loss);
  const Eigen::Matrix3d R = pose.rotation().Matrix();
  // r = L^T e, e = q + t - mu with q = R p; dr/ddt = L^T and
  // dr/ddphi = -L^T R [p]x = -L^T [q]x R. R is common to all terms, so the
  // sums are taken without it and applied once: with Sigma^-1 = L L^T,
  // H_tt = sum w Sigma^-1, H_tr = (sum -w Sigma^-1 [q]x) R,
  // H_rr = R^T (sum w [q]x^T Sigma^-1 [q]x) R, g_t = sum w Sigma^-1 e,
  // g_r = R^T (sum w [q]x Sigma^-1 e).
  // Sums of one term at a time, and of pairs of terms in SIMD lanes.
  GeometricSums<double> single(0.0);
  GeometricSums<Eigen::Array2d> pairs(Eigen::Array2d::Zero());
  // Loss curvature (loss_curvature), with J^T r = [I_e; R^T (q x I_e)]
  // (I_e = Sigma^-1 e): summed without R as well.
  Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
  const auto weight_of = [&](double s, const Eigen::Vector3d& q, const Eigen::Vector3d& information_e) {
    double second = 0.0;
    const double weight = loss.Add(s, &second);
    if (loss_curvature && second != 0.0) {
      Eigen::Matrix<double, 6, 1> Jt_r;
      Jt_r << information_e, q.cross(information_e);
      C.noalias() += CurvatureAlongResidual(s, weight, second) * Jt_r * Jt_r.transpose();
    }
    return weight;
  };
  const std::size_t n = c.geometric.size();
  std::size_t k = 0;
  for (; k + 1 < n; k += 2) {
    const GeometricTermInputs<Eigen::Array2d> in = Inputs<Eigen::Array2d>(c, k, R, pose.translation());
    AddGeometricTerm(in, pairs, [&](const Eigen::Array2d& s, const Eigen::Array2d* information_e) {
      const auto lane = [&](const Eigen::Array2d* v, int l) { return Eigen::Vector3d(v[0][l], v[1][l], v[2][l]); };
      const double weight_a = weight_of(s[0], lane(in.q, 0), lane(information_e, 0));  // in term order
      return Eigen::Array2d(weight_a, weight_of(s[1], lane(in.q, 1), lane(information_e, 1)));
    });
  }
  for (; k < n; ++k) {
    const GeometricTermInputs<double> in = Inputs<double>(c, k, R, pose.translation());
    AddGeometricTerm(in, single, [&](double s, const double* information_e) {
      return weight_of(s, Eigen::Vector3d(in.q), Eigen::Vector3d(information_e));
    });
  }
  AddRotatedSums(single, pairs, R, system);
  if (loss_curvature) {
    Eigen::Matrix<double, 6, 6> rotate = Eigen::Matrix<double, 6, 6>::Identity();
    rotate.block<3, 3>(kRotationOffset, kRotationOffset) = R;
    system.loss_curvature = rotate.transpose() * C * rotate;
  }
  system.residuals = c.geometric.size();
  system.rho_sum = loss.Sum();
  return system;
}

LinearSystem BuildRcsSystem(const Correspondences& c, const SE3d& pose, const ScanMatchingOptions& options,
                            bool loss_curvature) {
  LinearSystem system;
  LossSum loss(options.rcs_loss);
  // Rotation-only: the translation is the association's constant.
  const bool rotation_only = options.rcs_translation == RcsTranslation::kRotationOnly;
  const Eigen::Vector3d translation = rotation_only ? c.pose.translation() : pose.translation();
  const Eigen::Matrix3d Rt = pose.rotation().Matrix().transpose();
  const Eigen::Matrix<double, 4, 3> P = QuaternionTangent(pose.rotation());
  for (const RcsTerm& term : c.rcs) {
    Eigen::Matrix<double, 1, 1> r;
    Eigen::Matrix<double, 1, 3> J_rotation, J_translation;
    if (options.jacobians == JacobianMode::kAnalytic) {
      // du/ddt = R^T, du/ddphi = -[mu_r]x (conventions.hpp: right perturbation),
      // so dr/ddphi = -dr/du [mu_r]x = (mu_r x dr/du^T)^T.
      const Eigen::Vector3d mean_radar = Rt * (term.mean - translation);
      const RcsLinearisation lin = LineariseRcs(term, mean_radar);
      r[0] = lin.residual;
      J_rotation = mean_radar.cross(lin.dr_du.transpose()).transpose();
      if (!rotation_only) J_translation = lin.dr_du * Rt;
    } else {
      Jet7 rotation[4], t[3], residual[1];
      SeedJets(pose, translation, rotation, t);
      const RcsResidual functor(term);
      functor(rotation, t, residual);
      r[0] = residual[0].a;
      J_rotation = residual[0].v.head<4>().transpose() * P;
      J_translation = residual[0].v.tail<3>().transpose();
    }
    if (rotation_only) {
      Accumulate(system, kRotationOffset, J_rotation, r, loss, loss_curvature);
    } else {
      Eigen::Matrix<double, 1, 6> J;
      J.block<1, 3>(0, kTranslationOffset) = J_translation;
      J.block<1, 3>(0, kRotationOffset) = J_rotation;
      Accumulate(system, 0, J, r, loss, loss_curvature);
    }
  }
  if (rotation_only) {
    // The paper: translation rows/columns of the RCS Hessian -> identity,
    // translation gradient -> zero (only the rotation block was accumulated).
    system.H.block<3, 3>(kTranslationOffset, kTranslationOffset).setIdentity();
  }
  system.rho_sum = loss.Sum();
  return system;
}

CombinedSystem BuildCombinedSystem(const Correspondences& c, const SE3d& pose, const ScanMatchingOptions& options,
                                   const ScanPriors& priors, bool loss_curvature) {
  CombinedSystem combined;
  const double w = options.w_rcs;
  const auto add = [&](const LinearSystem& system, double weight) {
    combined.H += weight * system.H;
    combined.loss_curvature += weight * system.loss_curvature;
    combined.g += weight * system.g;
    combined.cost += weight * system.rho_sum;
  };
  if (w < 1.0) {
    const LinearSystem geometric = BuildGeometricSystem(c, pose, options, loss_curvature);
    add(geometric, (1.0 - w) / double(geometric.residuals));
  }
  if (w > 0.0) {
    const LinearSystem rcs = BuildRcsSystem(c, pose, options, loss_curvature);
    add(rcs, w / double(rcs.residuals));
  }
  if (priors.velocity && priors.velocity->weight > 0.0) {  // linear in t: J = W R_prev^T
    const VelocityPrior& prior = *priors.velocity;
    const Eigen::Matrix3d J = prior.Jacobian();
    const Eigen::Vector3d r = prior.Residual(pose.translation());
    combined.H.block<3, 3>(kTranslationOffset, kTranslationOffset) += prior.weight * J.transpose() * J;
    combined.g.segment<3>(kTranslationOffset) += prior.weight * J.transpose() * r;
    combined.cost += prior.weight * r.squaredNorm();
  }
  if (priors.rotation && priors.rotation->weight > 0.0) {  // J = W Jr^-1(Log(R_pred^T R))
    const RotationPrior& prior = *priors.rotation;
    const Eigen::Matrix3d J = prior.Jacobian(pose.rotation());
    const Eigen::Vector3d r = prior.Residual(pose.rotation());
    combined.H.block<3, 3>(kRotationOffset, kRotationOffset) += prior.weight * J.transpose() * J;
    combined.g.segment<3>(kRotationOffset) += prior.weight * J.transpose() * r;
    combined.cost += prior.weight * r.squaredNorm();
  }
  return combined;
}

Eigen::Matrix<double, 6, 6> InformationMatrix(const Correspondences& c, const SE3d& pose,
                                              const ScanMatchingOptions& options) {
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  const double w = options.w_rcs;
  if (w < 1.0 && !c.geometric.empty()) {
    H += (1.0 - w) / double(c.geometric.size()) * BuildGeometricSystem(c, pose, options).H;
  }
  if (w > 0.0 && !c.rcs.empty()) {
    LinearSystem rcs = BuildRcsSystem(c, pose, options);
    if (options.rcs_translation == RcsTranslation::kRotationOnly) {
      rcs.H.block<3, 3>(kTranslationOffset, kTranslationOffset).setZero();
    }
    H += w / double(c.rcs.size()) * rcs.H;
  }
  return H;
}

}  // namespace radargauss
