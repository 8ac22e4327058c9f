// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/residuals/radar_inertial_residuals.hpp"

#include <cmath>

#include "radargauss/lie/manifold.hpp"

namespace radargauss {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// The state moved by d, with the pieces the Jacobians reuse.
struct Moved {
  SO3d R, R_d;  // R and R Exp(w d)
  Vector3d omega, v, v_d, a_b, p_shift;
  double d = 0.0;
  Matrix3d Jr;  // Jr(w d)
};

Moved Move(const double* rotation, const double* motion, const double* clock_offset, const ImuAtScan& imu) {
  Moved m;
  const Eigen::Map<const Vector3d> v(motion + kMotionVelocity), bg(motion + kMotionGyroBias);
  const Eigen::Map<const Vector3d> ba(motion + kMotionAccelBias);
  m.d = clock_offset[0] - imu.clock_offset;
  m.R = SO3d::FromXyzw(rotation);
  m.omega = imu.gyro - bg;
  m.R_d = m.R * SO3d::Exp(m.omega * m.d);
  m.v = v;
  m.a_b = imu.accel - ba;
  m.p_shift = v * m.d;
  m.v_d = v + (m.R * m.a_b + Vector3d(0.0, 0.0, -kGravity)) * m.d;
  m.Jr = SO3d::RightJacobian(m.omega * m.d);
  return m;
}

// J (tangent, rotations on the right) into the ambient quaternion's columns: times 4 P^T.
template <int Rows>
void QuaternionColumns(const Eigen::Matrix<double, Rows, 3>& tangent, const double* q, double* out) {
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> P;
  SO3Manifold().PlusJacobian(q, P.data());
  Eigen::Map<Eigen::Matrix<double, Rows, 4, Eigen::RowMajor>> J(out);
  J = 4.0 * tangent * P.transpose();
}

template <int Rows, int Cols>
void Columns(const Eigen::Matrix<double, Rows, Cols>& J, double* out) {
  Eigen::Map<Eigen::Matrix<double, Rows, Cols, Cols == 1 ? Eigen::ColMajor : Eigen::RowMajor>> map(out);
  map = J;
}

}  // namespace

// x = p_d + R_d t_e, e_t = A x - t_z, e_R = Log(R_z^T A R_d R_e); with the
// right perturbations: de_t/dphi = -A R [Exp(w d) t_e]x, de_R/dphi =
// Jr^-1(e_R) (Exp(w d) R_e)^T; de_t/db_g = A R_d [t_e]x Jr(w d) d,
// de_R/db_g = -Jr^-1(e_R) R_e^T Jr(w d) d; de/dt_d = [A (v + R_d (w x t_e)); Jr^-1(e_R) R_e^T w].
bool RadarPoseCostFunction::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Moved m = Move(parameters[0], parameters[2], parameters[6], imu_);
  const Eigen::Map<const Vector3d> p(parameters[1]), t_e(parameters[4]);
  const SO3d R_e = SO3d::FromXyzw(parameters[3]);
  const SO3d A = TiltRotation(parameters[5]);
  const SO3d Rx = SO3d::Exp(Vector3d(parameters[5][0], 0.0, 0.0));
  const Vector3d x = p + m.p_shift + m.R_d * t_e;
  const SO3d E = measured_.rotation().Inverse() * A * m.R_d * R_e;
  Eigen::Matrix<double, 6, 1> error;
  error.segment<3>(kTranslationOffset) = A * x - measured_.translation();
  error.segment<3>(kRotationOffset) = E.Log();
  Eigen::Map<Eigen::Matrix<double, 6, 1>> r(residuals);
  r = sqrt_information_ * error;
  if (jacobians == nullptr) return true;

  const Matrix3d Am = A.Matrix(), Jri = SO3d::RightJacobianInverse(error.segment<3>(kRotationOffset));
  const Matrix3d step = SO3d::Exp(m.omega * m.d).Matrix();
  const Matrix3d rotated_extrinsic_T = (SO3d::Exp(m.omega * m.d) * R_e).Inverse().Matrix();  // (Exp(w d) R_e)^T
  const Matrix3d R_e_T = R_e.Inverse().Matrix();
  const auto W = [&](const auto& J) { return (sqrt_information_ * J).eval(); };
  if (jacobians[0] != nullptr) {
    Eigen::Matrix<double, 6, 3> J = Eigen::Matrix<double, 6, 3>::Zero();
    J.block<3, 3>(kTranslationOffset, 0) = -Am * m.R.Matrix() * SO3d::Hat(step * t_e);
    J.block<3, 3>(kRotationOffset, 0) = Jri * rotated_extrinsic_T;
    QuaternionColumns<6>(W(J), parameters[0], jacobians[0]);
  }
  if (jacobians[1] != nullptr) {
    Eigen::Matrix<double, 6, 3> J = Eigen::Matrix<double, 6, 3>::Zero();
    J.block<3, 3>(kTranslationOffset, 0) = Am;
    Columns<6, 3>(W(J), jacobians[1]);
  }
  if (jacobians[2] != nullptr) {
    Eigen::Matrix<double, 6, 9> J = Eigen::Matrix<double, 6, 9>::Zero();
    J.block<3, 3>(kTranslationOffset, kMotionVelocity) = Am * m.d;
    J.block<3, 3>(kTranslationOffset, kMotionGyroBias) = Am * m.R_d.Matrix() * SO3d::Hat(t_e) * m.Jr * m.d;
    J.block<3, 3>(kRotationOffset, kMotionGyroBias) = -Jri * R_e_T * m.Jr * m.d;
    Columns<6, 9>(W(J), jacobians[2]);
  }
  if (jacobians[3] != nullptr) {
    Eigen::Matrix<double, 6, 3> J = Eigen::Matrix<double, 6, 3>::Zero();
    J.block<3, 3>(kRotationOffset, 0) = Jri;
    QuaternionColumns<6>(W(J), parameters[3], jacobians[3]);
  }
  if (jacobians[4] != nullptr) {
    Eigen::Matrix<double, 6, 3> J = Eigen::Matrix<double, 6, 3>::Zero();
    J.block<3, 3>(kTranslationOffset, 0) = Am * m.R_d.Matrix();
    Columns<6, 3>(W(J), jacobians[4]);
  }
  if (jacobians[5] != nullptr) {
    // A = Ry(pitch) Rx(roll): roll turns x about A's e_x, pitch turns A x about the world's e_y.
    const Matrix3d Q_T = (m.R_d * R_e).Inverse().Matrix();
    Eigen::Matrix<double, 6, 2> J = Eigen::Matrix<double, 6, 2>::Zero();
    J.block<3, 1>(kTranslationOffset, 0) = Am * Vector3d::UnitX().cross(x);
    J.block<3, 1>(kTranslationOffset, 1) = Vector3d::UnitY().cross(Am * x);
    J.block<3, 1>(kRotationOffset, 0) = Jri * Q_T * Vector3d::UnitX();
    J.block<3, 1>(kRotationOffset, 1) = Jri * Q_T * (Rx.Inverse() * Vector3d::UnitY());
    Columns<6, 2>(W(J), jacobians[5]);
  }
  if (jacobians[6] != nullptr) {
    Eigen::Matrix<double, 6, 1> J;
    J.segment<3>(kTranslationOffset) = Am * (m.v + m.R_d * m.omega.cross(t_e));
    J.segment<3>(kRotationOffset) = Jri * R_e_T * m.omega;
    Columns<6, 1>(W(J), jacobians[6]);
  }
  return true;
}

// u = R_d^T v_d + w x t_e, e = v_r - R_e^T u: du/dphi = Exp(w d)^T ([R^T v_d]x - [a_b]x d),
// du/dv = R_d^T, du/db_a = -Exp(w d)^T d, du/db_g = -[R_d^T v_d]x Jr(w d) d + [t_e]x,
// du/dt_e = [w]x, du/dt_d = [R_d^T v_d]x Jr(w d) w + Exp(w d)^T (a_b + R^T g); de/dphi_e = -[R_e^T u]x;
// de/db = dL/ddelta = |v_r| (sin(el - delta) h, -cos(el - delta)), h the horizontal direction.
bool RadarVelocityCostFunction::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Moved m = Move(parameters[0], parameters[1], parameters[4], imu_);
  const SO3d R_e = SO3d::FromXyzw(parameters[2]);
  const Eigen::Map<const Vector3d> t_e(parameters[3]);
  const Vector3d in_imu = m.R_d.Inverse() * m.v_d;
  const Vector3d u = in_imu + m.omega.cross(t_e);
  const Vector3d predicted = R_e.Inverse() * u;
  const double delta = parameters[5][0] - elevation_bias_removed_;
  Eigen::Map<Vector3d> r(residuals);
  r = sqrt_information_ * (LowerElevation(radar_velocity_, delta) - predicted);
  if (jacobians == nullptr) return true;

  const Matrix3d step_T = SO3d::Exp(m.omega * m.d).Inverse().Matrix();
  const Matrix3d minus_WR_e_T = -sqrt_information_ * R_e.Inverse().Matrix();  // de/du, weighted
  if (jacobians[0] != nullptr) {
    const Matrix3d du = step_T * (SO3d::Hat(m.R.Inverse() * m.v_d) - SO3d::Hat(m.a_b) * m.d);
    QuaternionColumns<3>(Eigen::Matrix3d(minus_WR_e_T * du), parameters[0], jacobians[0]);
  }
  if (jacobians[1] != nullptr) {
    Eigen::Matrix<double, 3, 9> du = Eigen::Matrix<double, 3, 9>::Zero();
    du.block<3, 3>(0, kMotionVelocity) = m.R_d.Inverse().Matrix();
    du.block<3, 3>(0, kMotionGyroBias) = -SO3d::Hat(in_imu) * m.Jr * m.d + SO3d::Hat(t_e);
    du.block<3, 3>(0, kMotionAccelBias) = -step_T * m.d;
    Columns<3, 9>(Eigen::Matrix<double, 3, 9>(minus_WR_e_T * du), jacobians[1]);
  }
  if (jacobians[2] != nullptr) {
    QuaternionColumns<3>(Eigen::Matrix3d(-sqrt_information_ * SO3d::Hat(predicted)), parameters[2], jacobians[2]);
  }
  if (jacobians[3] != nullptr) {
    Columns<3, 3>(Eigen::Matrix3d(minus_WR_e_T * SO3d::Hat(m.omega)), jacobians[3]);
  }
  if (jacobians[4] != nullptr) {
    const Vector3d du =
        SO3d::Hat(in_imu) * m.Jr * m.omega + step_T * (m.a_b + m.R.Inverse() * Vector3d(0.0, 0.0, -kGravity));
    Columns<3, 1>(Eigen::Matrix<double, 3, 1>(minus_WR_e_T * du), jacobians[4]);
  }
  if (jacobians[5] != nullptr) {
    const double horizontal = std::hypot(radar_velocity_.x(), radar_velocity_.y());
    Vector3d dL = Vector3d::Zero();
    if (horizontal >= 1e-9) {
      const double elevation = std::atan2(radar_velocity_.z(), horizontal), speed = radar_velocity_.norm();
      const double across = speed * std::sin(elevation - delta) / horizontal;
      dL << across * radar_velocity_.x(), across * radar_velocity_.y(), -speed * std::cos(elevation - delta);
    }
    Columns<3, 1>(Eigen::Matrix<double, 3, 1>(sqrt_information_ * dL), jacobians[5]);
  }
  return true;
}

// u = R^T v: du/dphi = [R^T v]x, du/dv = R^T; the rows of u's y and z.
bool VehicleMotionCostFunction::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const SO3d R = SO3d::FromXyzw(parameters[0]);
  const Vector3d u = R.Inverse() * Eigen::Map<const Vector3d>(parameters[1] + kMotionVelocity);
  residuals[0] = weight_ * u.y();
  residuals[1] = weight_ * u.z();
  if (jacobians == nullptr) return true;
  if (jacobians[0] != nullptr) {
    const Eigen::Matrix<double, 2, 3> J = weight_ * SO3d::Hat(u).bottomRows<2>();
    QuaternionColumns<2>(J, parameters[0], jacobians[0]);
  }
  if (jacobians[1] != nullptr) {
    Eigen::Matrix<double, 2, 9> J = Eigen::Matrix<double, 2, 9>::Zero();
    J.block<2, 3>(0, kMotionVelocity) = weight_ * R.Inverse().Matrix().bottomRows<2>();
    Columns<2, 9>(J, jacobians[1]);
  }
  return true;
}

}  // namespace radargauss
