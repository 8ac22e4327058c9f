#include "solvers/gauss_newton.hpp"

#include <ceres/jet.h>

#include <chrono>
#include <cmath>

#include <Eigen/Cholesky>

#include "radargauss/conventions.hpp"
#include "radargauss/lie/manifold.hpp"
#include "residuals/geometric_residual.hpp"

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

void Accumulate(LinearSystem& system, const Eigen::Ref<const Eigen::MatrixXd>& J,
                const Eigen::Ref<const Eigen::VectorXd>& r, const RobustLoss& loss) {
  double rho = 0.0, weight = 0.0;
  loss.Evaluate(r.squaredNorm(), rho, weight);
  system.H.noalias() += weight * J.transpose() * J;
  system.g.noalias() += weight * J.transpose() * r;
  ++system.residuals;
}

}  // namespace

LinearSystem BuildGeometricSystem(const Correspondences& c, const MatchingMap& map,
                                  const SE3d& pose, const ScanMatchingOptions& options) {
  LinearSystem system;
  const RobustLoss loss(options.geometric_loss);
  const Eigen::Matrix3d R = pose.rotation().Matrix();
  const Eigen::Matrix<double, 4, 3> P = QuaternionTangent(pose.rotation());
  for (const GeometricTerm& term : c.geometric) {
    const Eigen::Matrix3d& LT = map.index().SqrtInformationT(term.gaussian);
    const Eigen::Vector3d& mean = map.index().Mean(term.gaussian);
    Eigen::Vector3d r;
    Matrix3x6 J;
    if (options.jacobians == JacobianMode::kAnalytic) {
      // r = L^T (R p + t - mu); dr/ddt = L^T, dr/ddphi = -L^T R [p]x.
      r = LT * (R * term.point_radar + pose.translation() - mean);
      J.block<3, 3>(0, kTranslationOffset) = LT;
      J.block<3, 3>(0, kRotationOffset) = -LT * R * SO3d::Hat(term.point_radar);
    } else {
      Jet7 rotation[4], t[3], residual[3];
      SeedJets(pose, pose.translation(), rotation, t);
      const GeometricResidual functor(term.point_radar, mean, LT);
      functor(rotation, t, residual);
      Eigen::Matrix<double, 3, 7> ambient;
      for (int i = 0; i < 3; ++i) {
        r[i] = residual[i].a;
        ambient.row(i) = residual[i].v.transpose();
      }
      J.block<3, 3>(0, kTranslationOffset) = ambient.rightCols<3>();
      J.block<3, 3>(0, kRotationOffset) = ambient.leftCols<4>() * P;
    }
    Accumulate(system, J, r, loss);
  }
  return system;
}

LinearSystem BuildRcsSystem(const Correspondences& c, const SE3d& pose,
                            const ScanMatchingOptions& options) {
  LinearSystem system;
  const RobustLoss loss(options.rcs_loss);
  // Rotation-only: the translation is the association's constant.
  const Eigen::Vector3d translation =
      options.rcs_translation == RcsTranslation::kRotationOnly ? c.translation : pose.translation();
  const Eigen::Matrix3d Rt = pose.rotation().Matrix().transpose();
  const Eigen::Matrix<double, 4, 3> P = QuaternionTangent(pose.rotation());
  for (const RcsTerm& term : c.rcs) {
    Eigen::Matrix<double, 1, 1> r;
    Eigen::Matrix<double, 1, 6> J;
    if (options.jacobians == JacobianMode::kAnalytic) {
      // du/ddt = R^T, du/ddphi = -[mu_r]x (conventions.hpp: right perturbation).
      const RcsLinearisation lin = LineariseRcs(term, pose.rotation().quaternion(), translation);
      r[0] = lin.residual;
      J.block<1, 3>(0, kTranslationOffset) = lin.dr_du * Rt;
      J.block<1, 3>(0, kRotationOffset) = -lin.dr_du * SO3d::Hat(lin.mean_radar);
    } else {
      Jet7 rotation[4], t[3], residual[1];
      SeedJets(pose, translation, rotation, t);
      const RcsResidual functor(term);
      functor(rotation, t, residual);
      r[0] = residual[0].a;
      J.block<1, 3>(0, kTranslationOffset) = residual[0].v.tail<3>().transpose();
      J.block<1, 3>(0, kRotationOffset) = residual[0].v.head<4>().transpose() * P;
    }
    Accumulate(system, J, r, loss);
  }
  if (options.rcs_translation == RcsTranslation::kRotationOnly) {
    // The paper: translation rows/columns of the RCS Hessian -> identity,
    // translation gradient -> zero.
    system.H.block<3, 3>(kTranslationOffset, kTranslationOffset).setIdentity();
    system.H.block<3, 3>(kTranslationOffset, kRotationOffset).setZero();
    system.H.block<3, 3>(kRotationOffset, kTranslationOffset).setZero();
    system.g.segment<3>(kTranslationOffset).setZero();
  }
  return system;
}

GaussNewtonSolver::GaussNewtonSolver(const ScanMatchingOptions& options) : options_(options) {
  ValidateOptions(options_);
}

std::string GaussNewtonSolver::Name() const {
  return options_.jacobians == JacobianMode::kAnalytic ? "gn" : "gn-autodiff";
}

ScanMatchingResult GaussNewtonSolver::Match(const RadarScan& scan, const MatchingMap& map,
                                            const SE3d& initial) const {
  const auto start = std::chrono::steady_clock::now();
  ScanMatchingResult result;
  result.pose = initial;
  const double w = options_.w_rcs;
  const bool with_rcs = w > 0.0;
  Correspondences c = FindCorrespondences(scan, map, result.pose, options_.gate, with_rcs);
  for (int iteration = 1; iteration <= options_.max_iterations; ++iteration) {
    if (options_.reassociate && iteration > 1) {
      c = FindCorrespondences(scan, map, result.pose, options_.gate, with_rcs);
    }
    if (!CheckCorrespondences(scan, c, options_, result.reason)) break;
    result.iterations = iteration;
    // Eq. 2: H = (1-w)/N_geo H_geo + w/N_rcs H_rcs (likewise g).
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    if (w < 1.0) {
      const LinearSystem geometric = BuildGeometricSystem(c, map, result.pose, options_);
      H += (1.0 - w) / double(geometric.residuals) * geometric.H;
      g += (1.0 - w) / double(geometric.residuals) * geometric.g;
    }
    if (w > 0.0) {
      const LinearSystem rcs = BuildRcsSystem(c, result.pose, options_);
      H += w / double(rcs.residuals) * rcs.H;
      g += w / double(rcs.residuals) * rcs.g;
    }
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(H);
    const Eigen::Matrix<double, 6, 1> pivots = ldlt.vectorD();
    if (ldlt.info() != Eigen::Success || !(pivots.minCoeff() > 1e-10 * std::max(1e-300, pivots.maxCoeff()))) {
      result.reason = "degenerate normal equations (too few or ill-placed residuals)";
      break;
    }
    const Eigen::Matrix<double, 6, 1> dx = ldlt.solve(-g);
    if (!dx.allFinite()) {
      result.reason = "non-finite update";
      break;
    }
    result.pose.translation() += dx.segment<3>(kTranslationOffset);
    result.pose.rotation() = result.pose.rotation() * SO3d::Exp(dx.segment<3>(kRotationOffset));
    if (dx.segment<3>(kTranslationOffset).norm() < options_.translation_tolerance &&
        dx.segment<3>(kRotationOffset).norm() < options_.rotation_tolerance) {
      result.converged = true;
      break;
    }
  }
  if (!result.converged && result.reason.empty()) result.reason = "iteration limit reached";
  if (result.iterations > 0) {
    const Correspondences final_c =
        options_.reassociate ? FindCorrespondences(scan, map, result.pose, options_.gate, with_rcs) : c;
    result.n_geo = final_c.geometric.size();
    result.n_rcs = final_c.rcs.size();
    result.final_cost = EvaluateCost(final_c, map, result.pose, options_);
  }
  if (!result.converged && !result.reason.empty() && result.iterations == 0) result.pose = initial;
  result.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace radargauss
