#include "solvers/gauss_newton.hpp"

#include <ceres/jet.h>

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

// The update of conventions.hpp: t += dt (world), R = R Exp(dphi) (radar frame).
SE3d Step(const SE3d& pose, const Eigen::Matrix<double, 6, 1>& dx) {
  return SE3d(pose.rotation() * SO3d::Exp(dx.segment<3>(kRotationOffset)),
              pose.translation() + dx.segment<3>(kTranslationOffset));
}

}  // namespace

LinearSystem BuildGeometricSystem(const Correspondences& c, const SE3d& pose,
                                  const ScanMatchingOptions& options) {
  LinearSystem system;
  const RobustLoss loss(options.geometric_loss);
  const Eigen::Matrix3d R = pose.rotation().Matrix();
  const Eigen::Matrix<double, 4, 3> P = QuaternionTangent(pose.rotation());
  for (const GeometricTerm& term : c.geometric) {
    const Eigen::Matrix3d& LT = c.index->SqrtInformationT(term.gaussian);
    const Eigen::Vector3d& mean = c.index->Mean(term.gaussian);
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
  return RunCoarseToFine(scan, map, initial, options_, [this](const LevelStep& level, ScanMatchingResult& result) {
    const Correspondences& c = level.correspondences;
    const double w = level.options.w_rcs;
    // Eq. 2: H = (1-w)/N_geo H_geo + w/N_rcs H_rcs (likewise g).
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    if (w < 1.0) {
      const LinearSystem geometric = BuildGeometricSystem(c, result.pose, level.options);
      H += (1.0 - w) / double(geometric.residuals) * geometric.H;
      g += (1.0 - w) / double(geometric.residuals) * geometric.g;
    }
    if (w > 0.0) {
      const LinearSystem rcs = BuildRcsSystem(c, result.pose, level.options);
      H += w / double(rcs.residuals) * rcs.H;
      g += w / double(rcs.residuals) * rcs.g;
    }
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(H);
    const Eigen::Matrix<double, 6, 1> pivots = ldlt.vectorD();
    if (ldlt.info() != Eigen::Success || !(pivots.minCoeff() > 1e-10 * std::max(1e-300, pivots.maxCoeff()))) {
      result.reason = "degenerate normal equations (too few or ill-placed residuals)";
      return StepOutcome::kFailed;
    }
    const Eigen::Matrix<double, 6, 1> dx = ldlt.solve(-g);
    if (!dx.allFinite()) {
      result.reason = "non-finite update";
      return StepOutcome::kFailed;
    }
    // Backtracking on the exact map: halve the step while eq. 2 grows for
    // this association (coarse levels only steer into the basin).
    const double cost = level.finest ? EvaluateCost(c, result.pose, level.options) : 0.0;
    double scale = 1.0;
    SE3d next = Step(result.pose, dx);
    for (int halving = 0; level.finest && halving < options_.max_step_halvings &&
                          EvaluateCost(c, next, level.options) > cost;
         ++halving) {
      scale *= 0.5;
      next = Step(result.pose, scale * dx);
    }
    result.pose = next;
    const Eigen::Matrix<double, 6, 1> step = scale * dx;
    const bool small = step.segment<3>(kTranslationOffset).norm() < level.looseness * options_.translation_tolerance &&
                       step.segment<3>(kRotationOffset).norm() < level.looseness * options_.rotation_tolerance;
    return small ? StepOutcome::kConverged : StepOutcome::kContinue;
  });
}

}  // namespace radargauss
