// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/lie/manifold.hpp"

#include <ceres/manifold_test_utils.h>
#include <gtest/gtest.h>

#include <random>

#include "support/test_util.hpp"

namespace radargauss {
namespace {

using testing::HardAngles;
using testing::NumericJacobian;
using testing::RandomUnitVector;

constexpr double kTolerance = 1e-9;

// Rotations at the hard angles and at random ones.
std::vector<SO3d> TestRotations() {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(0.0, M_PI);
  std::vector<SO3d> rotations;
  for (const double a : HardAngles()) rotations.push_back(SO3d::Exp(a * RandomUnitVector(rng)));
  for (int i = 0; i < 20; ++i) rotations.push_back(SO3d::Exp(angle(rng) * RandomUnitVector(rng)));
  return rotations;
}

TEST(SO3Manifold, InvariantsHold) {
  using namespace ceres;  // the invariants macro names ceres matchers unqualified
  const SO3Manifold manifold;
  std::mt19937 rng(5);
  for (const SO3d& rotation : TestRotations()) {
    const Eigen::VectorXd x = rotation.quaternion().coeffs();
    const Eigen::VectorXd delta = 0.7 * RandomUnitVector(rng);
    const Eigen::VectorXd y = SO3d::Exp(2.0 * RandomUnitVector(rng)).quaternion().coeffs();
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, kTolerance);
  }
}

TEST(SE3Manifold, InvariantsHold) {
  using namespace ceres;  // the invariants macro names ceres matchers unqualified
  const SE3Manifold manifold;
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> uniform(-5.0, 5.0);
  const auto random_translation = [&] { return Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)); };
  const auto ambient = [](const SE3d& pose) {
    Eigen::VectorXd v(7);
    v << pose.rotation().quaternion().coeffs(), pose.translation();
    return v;
  };
  for (const SO3d& rotation : TestRotations()) {
    const Eigen::VectorXd x = ambient(SE3d(rotation, random_translation()));
    Eigen::VectorXd delta(6);
    delta << random_translation(), 0.7 * RandomUnitVector(rng);
    const Eigen::VectorXd y = ambient(SE3d(SO3d::Exp(2.0 * RandomUnitVector(rng)), random_translation()));
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, kTolerance);
  }
}

// Central differences as well as Ceres's Ridders check.
TEST(Manifolds, PlusJacobiansMatchCentralDifferences) {
  const SO3Manifold so3;
  const SE3Manifold se3;
  for (const SO3d& rotation : TestRotations()) {
    const Eigen::Vector4d x = rotation.quaternion().coeffs();
    const Eigen::MatrixXd numeric = NumericJacobian(
        [&](const Eigen::VectorXd& d) {
          Eigen::VectorXd out(4);
          so3.Plus(x.data(), d.data(), out.data());
          return out;
        },
        Eigen::Vector3d::Zero());
    Eigen::Matrix<double, 4, 3, Eigen::RowMajor> analytic;
    so3.PlusJacobian(x.data(), analytic.data());
    EXPECT_LT((analytic - numeric).norm(), 1e-6);

    Eigen::Matrix<double, 7, 1> pose;
    pose << x, 1.0, -2.0, 3.0;
    const Eigen::MatrixXd numeric_se3 = NumericJacobian(
        [&](const Eigen::VectorXd& d) {
          Eigen::VectorXd out(7);
          se3.Plus(pose.data(), d.data(), out.data());
          return out;
        },
        Eigen::Matrix<double, 6, 1>::Zero());
    Eigen::Matrix<double, 7, 6, Eigen::RowMajor> analytic_se3;
    se3.PlusJacobian(pose.data(), analytic_se3.data());
    EXPECT_LT((analytic_se3 - numeric_se3).norm(), 1e-6);
  }
}

}  // namespace
}  // namespace radargauss
