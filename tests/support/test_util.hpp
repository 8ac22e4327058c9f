// SPDX-License-Identifier: BSD-3-Clause
// Shared helpers for the tests: central-difference Jacobians (the independent
// reference for every analytic Jacobian) and the list of hard rotation angles.
#pragma once

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Core>

namespace radargauss::testing {

// Rotation angles where exp/log and Jacobians are hard: 0, tiny, small, near pi.
inline const std::vector<double>& HardAngles() {
  static const std::vector<double> angles = {0.0, 1e-9, 1e-4, 0.3, 1.0, 2.5, M_PI - 1e-6};
  return angles;
}

// Central differences of f: R^n -> R^m at x with step h.
inline Eigen::MatrixXd NumericJacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                       const Eigen::VectorXd& x, double h = 1e-6) {
  const Eigen::VectorXd f0 = f(x);
  Eigen::MatrixXd J(f0.size(), x.size());
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd plus = x;
    Eigen::VectorXd minus = x;
    plus[i] += h;
    minus[i] -= h;
    J.col(i) = (f(plus) - f(minus)) / (2.0 * h);
  }
  return J;
}

inline Eigen::Vector3d RandomUnitVector(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
  return v.normalized();
}

}  // namespace radargauss::testing
