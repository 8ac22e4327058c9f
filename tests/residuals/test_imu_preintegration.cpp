// SPDX-License-Identifier: BSD-3-Clause
// IMU preintegration (docs/design/residuals.md, "IMU preintegration") against
// independent references: planted motions whose exact IMU integrates to
// their states to 1e-9, the first-order bias correction against integrating
// again (second-order agreement), and the covariance against Monte Carlo.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "radargauss/residuals/imu_preintegration.hpp"
#include "support/imu_fixtures.hpp"

namespace radargauss {
namespace {

using testing::IntegrateTurningDrive;
const Eigen::Vector3d kG = testing::kGravityVector;

struct State {
  SO3d R;
  Eigen::Vector3d v, p;
};

// The state at j predicted from i and the increments (the header's model).
State Predict(const State& i, const ImuDelta& d) {
  const double T = d.duration;
  return {i.R * d.rotation, i.v + kG * T + i.R * d.velocity, i.p + i.v * T + 0.5 * kG * T * T + i.R * d.position};
}

TEST(ImuPreintegration, ConstantRateAtConstantVelocityIntegratesExactly) {
  const Eigen::Vector3d omega(0.1, -0.2, 0.3), v0(3.0, -1.0, 0.5), p0(1.0, 2.0, 3.0);
  const SO3d R0 = SO3d::Exp(Eigen::Vector3d(0.3, -0.1, 1.2));
  const ImuBias bias{Eigen::Vector3d(0.01, -0.02, 0.005), Eigen::Vector3d(0.1, 0.05, -0.2)};
  ImuPreintegration between(bias, ImuNoise{});
  const double dt = 0.005;
  SO3d R = R0;
  for (int k = 0; k < 200; ++k) {
    between.Integrate(omega + bias.gyro, R.Inverse() * (-kG) + bias.accel, dt);  // at rest in a moving frame: f = -g
    R = R * SO3d::Exp(omega * dt);
  }
  const State j = Predict({R0, v0, p0}, between.delta());
  EXPECT_LT((R.Inverse() * j.R).Log().norm(), 1e-12);
  EXPECT_LT((j.v - v0).norm(), 1e-9);
  EXPECT_LT((j.p - (p0 + v0 * 1.0)).norm(), 1e-9);
}

TEST(ImuPreintegration, ConstantAccelerationIntegratesExactly) {
  const Eigen::Vector3d a(0.7, -0.4, 0.2), v0(5.0, 0.0, 0.0), p0(-2.0, 1.0, 0.0);
  const SO3d R0 = SO3d::Exp(Eigen::Vector3d(0.05, 0.02, -0.8));
  ImuPreintegration between(ImuBias{}, ImuNoise{});
  for (int k = 0; k < 400; ++k) between.Integrate(Eigen::Vector3d::Zero(), R0.Inverse() * (a - kG), 0.0025);
  const State j = Predict({R0, v0, p0}, between.delta());
  EXPECT_LT((j.v - (v0 + a * 1.0)).norm(), 1e-9);
  EXPECT_LT((j.p - (p0 + v0 * 1.0 + 0.5 * a)).norm(), 1e-9);
}

ImuDelta Integrated(const ImuBias& bias) { return IntegrateTurningDrive(bias, 200).delta(); }

double Difference(const ImuDelta& a, const ImuDelta& b) {
  return (a.rotation.Inverse() * b.rotation).Log().norm() + (a.velocity - b.velocity).norm() +
         (a.position - b.position).norm();
}

TEST(ImuPreintegration, FirstOrderBiasCorrectionAgreesWithIntegratingAgain) {
  const ImuBias linearisation{Eigen::Vector3d(0.002, -0.001, 0.003), Eigen::Vector3d(0.05, -0.02, 0.01)};
  ImuPreintegration between(linearisation, ImuNoise{});
  for (const auto& [gyro, accel] : testing::TurningDriveSamples(200)) between.Integrate(gyro, accel, 0.005);
  const Eigen::Vector3d direction_g(0.6, -0.8, 0.3), direction_a(-0.5, 0.2, 0.9);
  double previous = 0.0;
  for (const double step : {4e-3, 2e-3, 1e-3}) {
    const ImuBias moved{linearisation.gyro + step * direction_g, linearisation.accel + 10 * step * direction_a};
    const double error = Difference(between.Corrected(moved), Integrated(moved));
    const double uncorrected = Difference(between.delta(), Integrated(moved));
    EXPECT_LT(error, 1e-2 * uncorrected) << step;
    if (previous > 0.0) {
      EXPECT_NEAR(previous / error, 4.0, 1.0) << "second order: halving the change quarters the error";
    }
    previous = error;
  }
  const ImuBias far{linearisation.gyro + Eigen::Vector3d(0.02, 0.0, 0.0), linearisation.accel};
  EXPECT_FALSE(between.WithinCorrection(far));
  EXPECT_THROW(between.Corrected(far), std::out_of_range);
}

TEST(ImuPreintegration, CovarianceMatchesMonteCarlo) {
  ImuNoise noise;
  noise.gyro_noise_density = 2e-3;
  noise.accel_noise_density = 2e-2;
  const double dt = 0.005;
  ImuPreintegration mean(ImuBias{}, noise);
  for (const auto& [gyro, accel] : testing::TurningDriveSamples(200)) mean.Integrate(gyro, accel, dt);
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  const auto draw = [&](double std) -> Eigen::Vector3d {
    return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * std;
  };
  const int runs = 4000;
  Eigen::Matrix<double, 9, 9> sample = Eigen::Matrix<double, 9, 9>::Zero();
  for (int r = 0; r < runs; ++r) {
    ImuPreintegration noisy(ImuBias{}, noise);
    for (const auto& [gyro, accel] : testing::TurningDriveSamples(200)) {
      noisy.Integrate(gyro + draw(noise.gyro_noise_density / std::sqrt(dt)),
                      accel + draw(noise.accel_noise_density / std::sqrt(dt)), dt);
    }
    Eigen::Matrix<double, 9, 1> e;
    e << (mean.delta().rotation.Inverse() * noisy.delta().rotation).Log(),
        noisy.delta().velocity - mean.delta().velocity, noisy.delta().position - mean.delta().position;
    sample += e * e.transpose() / runs;
  }
  for (int d = 0; d < 9; ++d) {
    EXPECT_NEAR(sample(d, d), mean.covariance()(d, d), 0.1 * mean.covariance()(d, d)) << d;
  }
}

TEST(ImuPreintegration, RefusesBadSamples) {
  ImuPreintegration between(ImuBias{}, ImuNoise{});
  EXPECT_THROW(between.Integrate(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0.0), std::invalid_argument);
  EXPECT_THROW(between.Integrate(Eigen::Vector3d(NAN, 0, 0), Eigen::Vector3d::Zero(), 0.01), std::invalid_argument);
  ImuNoise bad;
  bad.gyro_noise_density = -1.0;
  EXPECT_THROW(ImuPreintegration(ImuBias{}, bad), std::invalid_argument);
}

}  // namespace
}  // namespace radargauss
