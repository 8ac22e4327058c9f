// SPDX-License-Identifier: BSD-3-Clause
// The preintegrated IMU term (docs/design/residuals.md, "The IMU term"): analytic
// Jacobians against automatic differentiation and central differences, and
// a zero residual at the states of a planted motion whose exact IMU it
// integrates; the radar's pose and velocity terms on an IMU state likewise.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "radargauss/residuals/imu_residual.hpp"
#include "radargauss/residuals/radar_inertial_residuals.hpp"
#include "support/cost_function_checks.hpp"
#include "support/imu_fixtures.hpp"

namespace radargauss {
namespace {

const Eigen::Vector3d kG = testing::kGravityVector;

// 0.5 s of the turning drive, integrated at `linearisation`.
ImuPreintegration DriveBetween(const ImuBias& linearisation) {
  return testing::IntegrateTurningDrive(linearisation, 100);
}

Eigen::Matrix<double, 9, 1> RandomMotion(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix<double, 9, 1> m;
  for (int k = 0; k < 3; ++k) {
    m(kMotionVelocity + k) = 5.0 * n(rng);
    m(kMotionGyroBias + k) = 0.004 * n(rng);
    m(kMotionAccelBias + k) = 0.08 * n(rng);
  }
  return m;
}

TEST(ImuResidualJacobians, AnalyticAutodiffNumeric) {
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const ImuBias linearisation{0.003 * testing::RandomUnitVector(rng), 0.05 * testing::RandomUnitVector(rng)};
    const ImuPreintegration between = DriveBetween(linearisation);
    const ImuCostFunction analytic(between, ImuNoise{});
    const std::unique_ptr<ceres::CostFunction> autodiff(ImuResidual::Create(between, ImuNoise{}));
    Eigen::Vector4d qi = SO3d::Exp(Eigen::Vector3d(n(rng), n(rng), n(rng))).quaternion().coeffs();
    Eigen::Vector4d qj = SO3d::Exp(Eigen::Vector3d(n(rng), n(rng), n(rng))).quaternion().coeffs();
    Eigen::Vector3d pi(n(rng), n(rng), n(rng)), pj(n(rng), n(rng), n(rng));
    pi *= 10.0;
    pj *= 10.0;
    Eigen::Matrix<double, 9, 1> mi = RandomMotion(rng), mj = RandomMotion(rng);
    const std::vector<double*> blocks = {qi.data(), pi.data(), mi.data(), qj.data(), pj.data(), mj.data()};
    std::vector<Eigen::MatrixXd> ja, jd;
    const Eigen::VectorXd ra = EvaluateWithJacobians(analytic, blocks, ja);
    const Eigen::VectorXd rd = EvaluateWithJacobians(*autodiff, blocks, jd);
    EXPECT_LT(Relative(ra, rd), 1e-12);
    for (int b = 0; b < 6; ++b) {
      EXPECT_LT(Relative(ja[b], jd[b]), 1e-8) << "block " << b;
      EXPECT_LT(Relative(ja[b], NumericBlockJacobian(analytic, blocks, b)), 1e-5) << "block " << b;
    }
  }
}

// A constant rate and a constant acceleration in the world, with biases:
// the exact samples make the states at both ends a zero of the term.
TEST(ImuResidual, ZeroAtThePlantedStates) {
  const Eigen::Vector3d omega(0.1, -0.05, 0.3), a(0.6, -0.3, 0.1), v0(4.0, 1.0, 0.0), p0(5.0, -2.0, 1.0);
  const ImuBias bias{Eigen::Vector3d(0.002, -0.001, 0.003), Eigen::Vector3d(0.04, -0.02, 0.06)};
  const SO3d R0 = SO3d::Exp(Eigen::Vector3d(0.02, -0.01, 0.7));
  ImuPreintegration between(bias, ImuNoise{});
  SO3d R = R0;
  const double dt = 0.004;
  const int steps = 250;
  for (int k = 0; k < steps; ++k) {
    // f = R^T (a - g) at the sample's start, where the integrator holds R.
    between.Integrate(omega + bias.gyro, R.Inverse() * (a - kG) + bias.accel, dt);
    R = R * SO3d::Exp(omega * dt);
  }
  // The world acceleration is a throughout: v and p follow exactly.
  const double T = steps * dt;
  Eigen::Vector4d qi = R0.quaternion().coeffs(), qj = R.quaternion().coeffs();
  Eigen::Vector3d pi = p0, pj = p0 + v0 * T + 0.5 * a * T * T;
  Eigen::Matrix<double, 9, 1> mi, mj;
  mi << v0, bias.gyro, bias.accel;
  mj << v0 + a * T, bias.gyro, bias.accel;
  const ImuCostFunction term(between, ImuNoise{});
  const double* blocks[] = {qi.data(), pi.data(), mi.data(), qj.data(), pj.data(), mj.data()};
  Eigen::Matrix<double, 15, 1> r;
  ASSERT_TRUE(term.Evaluate(blocks, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-5);
  // A wrong end velocity shows: 1 cm/s is many sigmas of half a second of a MEMS accelerometer.
  mj(kMotionVelocity) += 0.01;
  ASSERT_TRUE(term.Evaluate(blocks, r.data(), nullptr));
  EXPECT_GT(r.norm(), 1.0);
}

TEST(ImuResidual, NoSamplesIsRefused) {
  const ImuPreintegration empty(ImuBias{}, ImuNoise{});
  EXPECT_THROW(ImuCostFunction(empty, ImuNoise{}), std::invalid_argument);
}

// The radar's terms on an IMU state (docs/design/solvers.md, "The sliding window"):
// zero at a hand-made state and its exact measurements, and automatic
// differentiation against central differences on every block.
struct RadarOnImu {
  Eigen::Vector4d q = SO3d::Exp(Eigen::Vector3d(0.1, -0.05, 0.8)).quaternion().coeffs();
  Eigen::Vector3d p = Eigen::Vector3d(3.0, -1.0, 0.5);
  Eigen::Matrix<double, 9, 1> motion;
  Eigen::Vector4d qe = SO3d::Exp(Eigen::Vector3d(3.1, 0.02, 0.5)).quaternion().coeffs();  // an IMU upside down
  Eigen::Vector3d te = Eigen::Vector3d(1.2, -0.3, -0.4);
  Eigen::Vector2d tilt = Eigen::Vector2d(0.02, -0.015);
  RadarOnImu() { motion << 6.0, 0.5, -0.1, 0.002, -0.001, 0.003, 0.05, 0.02, -0.04; }
  SO3d R() const { return SO3d::FromXyzw(q.data()); }
  SO3d Re() const { return SO3d::FromXyzw(qe.data()); }
};

TEST(RadarPoseResidual, ZeroAtTheRadarsPoseAndAgreesWithCentralDifferences) {
  RadarOnImu s;
  const SO3d A = TiltRotation(s.tilt.data());
  const ImuAtScan imu{Eigen::Vector3d(0.05, -0.02, 0.7), Eigen::Vector3d(0.3, -0.2, 9.9), 0.010};
  double clock = 0.010;  // as the samples were read: the state stands at the scan
  // The radar in the matcher's world, composed by hand: A (R R_e, p + R t_e).
  const SE3d radar(A * s.R() * s.Re(), A * (s.p + s.R() * s.te));
  const std::unique_ptr<ceres::CostFunction> term(
      RadarPoseResidual::Create(radar, Eigen::Matrix<double, 6, 6>::Identity() * 10.0, imu));
  const std::vector<double*> blocks = {s.q.data(),  s.p.data(),    s.motion.data(), s.qe.data(),
                                       s.te.data(), s.tilt.data(), &clock};
  std::vector<Eigen::MatrixXd> J;
  EXPECT_LT(EvaluateWithJacobians(*term, blocks, J).norm(), 1e-12);
  // At an offset 20 ms later the scan saw the state moved by R Exp(w d), p + v d.
  clock = 0.030;
  EvaluateWithJacobians(*term, blocks, J);
  for (int b = 0; b < 7; ++b) EXPECT_LT(Relative(J[b], NumericBlockJacobian(*term, blocks, b)), 1e-5) << "block " << b;
  const Eigen::Vector3d omega = imu.gyro - s.motion.segment<3>(kMotionGyroBias);
  const SO3d R_d = s.R() * SO3d::Exp(omega * 0.020);
  const Eigen::Vector3d p_d = s.p + s.motion.segment<3>(kMotionVelocity) * 0.020;
  const SE3d later(A * R_d * s.Re(), A * (p_d + R_d * s.te));
  const std::unique_ptr<ceres::CostFunction> moved(
      RadarPoseResidual::Create(later, Eigen::Matrix<double, 6, 6>::Identity() * 10.0, imu));
  EXPECT_LT(EvaluateWithJacobians(*moved, blocks, J).norm(), 1e-12);
  for (int b = 0; b < 7; ++b) EXPECT_LT(Relative(J[b], NumericBlockJacobian(*moved, blocks, b)), 1e-5) << "block " << b;
  // 1 cm off along the world's x: 10 x 0.01 in the first residual.
  const SE3d off_pose(later.rotation(), later.translation() + Eigen::Vector3d(0.01, 0.0, 0.0));
  const std::unique_ptr<ceres::CostFunction> off(
      RadarPoseResidual::Create(off_pose, Eigen::Matrix<double, 6, 6>::Identity() * 10.0, imu));
  EXPECT_NEAR(EvaluateWithJacobians(*off, blocks, J)(kTranslationOffset), -0.1, 1e-12);
}

TEST(RadarVelocityResidual, ZeroAtTheLeverArmsVelocityAndAgreesWithCentralDifferences) {
  RadarOnImu s;
  const ImuAtScan imu{Eigen::Vector3d(0.05, -0.02, 0.7), Eigen::Vector3d(0.3, -0.2, 9.9), 0.0};
  double clock = 0.0, elevation_bias = 0.0;
  const Eigen::Vector3d omega = imu.gyro - s.motion.segment<3>(kMotionGyroBias);
  // The radar's velocity: the IMU's plus omega x t_e, in the radar frame.
  const Eigen::Vector3d world = s.motion.segment<3>(kMotionVelocity) + s.R() * omega.cross(s.te);
  const Eigen::Vector3d radar_velocity = (s.R() * s.Re()).Inverse() * world;
  const std::unique_ptr<ceres::CostFunction> term(
      RadarVelocityResidual::Create(radar_velocity, Eigen::Matrix3d::Identity() * 20.0, imu));
  const std::vector<double*> blocks = {s.q.data(), s.motion.data(), s.qe.data(), s.te.data(), &clock, &elevation_bias};
  std::vector<Eigen::MatrixXd> J;
  EXPECT_LT(EvaluateWithJacobians(*term, blocks, J).norm(), 1e-12);
  clock = -0.015;
  elevation_bias = 0.01;
  EvaluateWithJacobians(*term, blocks, J);
  for (int b = 0; b < 6; ++b) EXPECT_LT(Relative(J[b], NumericBlockJacobian(*term, blocks, b)), 1e-5) << "block " << b;
  clock = elevation_bias = 0.0;
  // Without the lever arm the residual is 20 |omega x t_e|.
  Eigen::Vector3d no_lever = Eigen::Vector3d::Zero();
  const std::vector<double*> without = {s.q.data(),      s.motion.data(), s.qe.data(),
                                        no_lever.data(), &clock,          &elevation_bias};
  EXPECT_NEAR(EvaluateWithJacobians(*term, without, J).norm(), 20.0 * omega.cross(s.te).norm(), 1e-9);
}

// A Doppler velocity raised by 0.7 deg of elevation (speed and azimuth kept,
// composed by hand) is zero at b = 0.7 deg; one raised by 0.3 deg, from a
// scan that had 0.4 deg removed, is zero at b = 0.7 deg too; lowering keeps the speed.
TEST(RadarVelocityResidual, ZeroWhereTheElevationBiasRaisedTheVelocity) {
  RadarOnImu s;
  const ImuAtScan imu{Eigen::Vector3d(0.05, -0.02, 0.7), Eigen::Vector3d(0.3, -0.2, 9.9), 0.0};
  const Eigen::Vector3d omega = imu.gyro - s.motion.segment<3>(kMotionGyroBias);
  const Eigen::Vector3d world = s.motion.segment<3>(kMotionVelocity) + s.R() * omega.cross(s.te);
  const Eigen::Vector3d truth = (s.R() * s.Re()).Inverse() * world;
  constexpr double kDeg = M_PI / 180.0;
  const auto raised_by = [&](double angle) -> Eigen::Vector3d {
    const double azimuth = std::atan2(truth.y(), truth.x());
    const double elevation = std::atan2(truth.z(), std::hypot(truth.x(), truth.y())) + angle;
    return truth.norm() * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                          std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  };
  const Eigen::Vector3d raised = raised_by(0.7 * kDeg);
  EXPECT_NEAR(LowerElevation(raised, 0.7 * kDeg).norm(), raised.norm(), 1e-12);
  double clock = 0.0, estimate = 0.7 * kDeg;
  const std::vector<double*> blocks = {s.q.data(), s.motion.data(), s.qe.data(), s.te.data(), &clock, &estimate};
  std::vector<Eigen::MatrixXd> J;
  const std::unique_ptr<ceres::CostFunction> term(
      RadarVelocityResidual::Create(raised, Eigen::Matrix3d::Identity() * 20.0, imu));
  EXPECT_LT(EvaluateWithJacobians(*term, blocks, J).norm(), 1e-10);
  const std::unique_ptr<ceres::CostFunction> partly(
      RadarVelocityResidual::Create(raised_by(0.3 * kDeg), Eigen::Matrix3d::Identity() * 20.0, imu, 0.4 * kDeg));
  EXPECT_LT(EvaluateWithJacobians(*partly, blocks, J).norm(), 1e-10);
  estimate = 0.3 * kDeg;  // the removed part forgotten
  EXPECT_GT(EvaluateWithJacobians(*partly, blocks, J).norm(), 1e-3);
  // A velocity with no horizontal part is left as it is.
  EXPECT_EQ(LowerElevation(Eigen::Vector3d(0.0, 0.0, 2.0), 0.3), Eigen::Vector3d(0.0, 0.0, 2.0));
}

// The analytic twins of the radar's terms against automatic differentiation
// (1e-8) and central differences (1e-5), at random states, extrinsics, tilts,
// clock offsets away from the samples' reading and elevation biases.
TEST(RadarTermJacobians, AnalyticAutodiffNumeric) {
  std::mt19937 rng(21);
  std::normal_distribution<double> n(0.0, 1.0);
  const auto vector = [&](double std) -> Eigen::Vector3d { return Eigen::Vector3d(n(rng), n(rng), n(rng)) * std; };
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Vector4d q = SO3d::Exp(vector(1.0)).quaternion().coeffs(), qe = SO3d::Exp(vector(1.5)).quaternion().coeffs();
    Eigen::Vector3d p = vector(10.0), te = vector(0.8);
    Eigen::Matrix<double, 9, 1> motion;
    motion << vector(5.0), vector(0.01), vector(0.1);
    Eigen::Vector2d tilt(0.05 * n(rng), 0.05 * n(rng));
    double clock = 0.03 * n(rng);
    const ImuAtScan imu{vector(0.5), vector(2.0) + Eigen::Vector3d(0, 0, 9.8), 0.02 * n(rng)};
    Eigen::Matrix<double, 6, 6> W6 = Eigen::Matrix<double, 6, 6>::Identity() * 5.0;
    W6(0, 4) = 1.0;
    Eigen::Matrix3d W3 = Eigen::Matrix3d::Identity() * 7.0;
    W3(1, 2) = -2.0;
    const SE3d measured = SE3d(SO3d::Exp(vector(1.0)), vector(10.0));
    const RadarPoseCostFunction pose(measured, W6, imu);
    const std::unique_ptr<ceres::CostFunction> pose_autodiff(RadarPoseResidual::Create(measured, W6, imu));
    const std::vector<double*> pose_blocks = {q.data(),  p.data(),    motion.data(), qe.data(),
                                              te.data(), tilt.data(), &clock};
    std::vector<Eigen::MatrixXd> ja, jd;
    EXPECT_LT(
        Relative(EvaluateWithJacobians(pose, pose_blocks, ja), EvaluateWithJacobians(*pose_autodiff, pose_blocks, jd)),
        1e-12);
    for (int b = 0; b < 7; ++b) {
      EXPECT_LT(Relative(ja[b], jd[b]), 1e-8) << "pose block " << b;
      EXPECT_LT(Relative(ja[b], NumericBlockJacobian(pose, pose_blocks, b)), 1e-5) << "pose block " << b;
    }
    const Eigen::Vector3d radar_velocity = vector(5.0);
    const double removed = 0.01 * n(rng);
    double elevation_bias = 0.02 * n(rng);
    const RadarVelocityCostFunction velocity(radar_velocity, W3, imu, removed);
    const std::unique_ptr<ceres::CostFunction> velocity_autodiff(
        RadarVelocityResidual::Create(radar_velocity, W3, imu, removed));
    const std::vector<double*> velocity_blocks = {q.data(),  motion.data(), qe.data(),
                                                  te.data(), &clock,        &elevation_bias};
    EXPECT_LT(Relative(EvaluateWithJacobians(velocity, velocity_blocks, ja),
                       EvaluateWithJacobians(*velocity_autodiff, velocity_blocks, jd)),
              1e-12);
    for (int b = 0; b < 6; ++b) {
      EXPECT_LT(Relative(ja[b], jd[b]), 1e-8) << "velocity block " << b;
      EXPECT_LT(Relative(ja[b], NumericBlockJacobian(velocity, velocity_blocks, b)), 1e-5) << "velocity block " << b;
    }
  }
}

// The vehicle's motion term: zero for a velocity along the IMU's x, the
// lateral and vertical parts weighted otherwise; analytic = autodiff (1e-8)
// = central differences (1e-5) on random states.
TEST(VehicleMotionResidual, ZeroAlongTheImusXAndAnalyticAutodiffNumeric) {
  Eigen::Vector4d q = SO3d::Exp(Eigen::Vector3d(0.05, -0.1, 1.2)).quaternion().coeffs();
  Eigen::Matrix<double, 9, 1> motion = Eigen::Matrix<double, 9, 1>::Zero();
  motion.segment<3>(kMotionVelocity) = SO3d::FromXyzw(q.data()) * Eigen::Vector3d(8.0, 0.0, 0.0);
  const VehicleMotionCostFunction analytic(0.1);
  const std::unique_ptr<ceres::CostFunction> autodiff(VehicleMotionResidual::Create(0.1));
  std::vector<double*> blocks = {q.data(), motion.data()};
  std::vector<Eigen::MatrixXd> ja, jd;
  EXPECT_LT(EvaluateWithJacobians(analytic, blocks, ja).norm(), 1e-12);
  motion.segment<3>(kMotionVelocity) = SO3d::FromXyzw(q.data()) * Eigen::Vector3d(8.0, 0.3, -0.2);
  const Eigen::VectorXd r = EvaluateWithJacobians(analytic, blocks, ja);
  EXPECT_NEAR(r(0), 3.0, 1e-12);
  EXPECT_NEAR(r(1), -2.0, 1e-12);
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    q = SO3d::Exp(Eigen::Vector3d(n(rng), n(rng), n(rng))).quaternion().coeffs();
    for (int i = 0; i < 9; ++i) motion(i) = 5.0 * n(rng);
    EXPECT_LT(Relative(EvaluateWithJacobians(analytic, blocks, ja), EvaluateWithJacobians(*autodiff, blocks, jd)),
              1e-12);
    for (int b = 0; b < 2; ++b) {
      EXPECT_LT(Relative(ja[b], jd[b]), 1e-8) << "block " << b;
      EXPECT_LT(Relative(ja[b], NumericBlockJacobian(analytic, blocks, b)), 1e-5) << "block " << b;
    }
  }
}

}  // namespace
}  // namespace radargauss
