// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/core/sh.hpp"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "support/test_util.hpp"

namespace radargauss {
namespace {

using testing::NumericJacobian;
using testing::RandomUnitVector;
constexpr int kCount = ShCoefficientCount(kMaxShDegree);

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n).
void GaussLegendre(int n, std::vector<double>& nodes, std::vector<double>& weights) {
  nodes.resize(n);
  weights.resize(n);
  for (int i = 0; i < n; ++i) {
    double x = std::cos(M_PI * (i + 0.75) / (n + 0.5));
    double dp = 0.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0;
      double p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      const double step = p1 / dp;
      x -= step;
      if (std::abs(step) < 1e-16) break;
    }
    nodes[i] = x;
    weights[i] = 2.0 / ((1.0 - x * x) * dp * dp);
  }
}

// Independent reference: real SH from associated Legendre polynomials with
// the Condon-Shortley phase, Y_l^m = sqrt(2) K P_l^|m| cos(m phi) (m > 0),
// sqrt(2) K P_l^|m| sin(|m| phi) (m < 0), K P_l^0 (m = 0), index l^2 + l + m.
double AssociatedLegendre(int l, int m, double x) {
  double pmm = 1.0;  // P_m^m = (-1)^m (2m-1)!! (1 - x^2)^(m/2)
  const double somx2 = std::sqrt(std::max(0.0, 1.0 - x * x));
  for (int i = 1; i <= m; ++i) pmm *= -(2.0 * i - 1.0) * somx2;
  if (l == m) return pmm;
  double pmmp1 = x * (2.0 * m + 1.0) * pmm;
  for (int ll = m + 2; ll <= l; ++ll) {
    const double pll = ((2.0 * ll - 1.0) * x * pmmp1 - (ll + m - 1.0) * pmm) / (ll - m);
    pmm = pmmp1;
    pmmp1 = pll;
  }
  return pmmp1;
}

double ReferenceSh(int l, int m, const Eigen::Vector3d& d) {
  const double theta = std::acos(std::clamp(d.z(), -1.0, 1.0));
  const double phi = std::atan2(d.y(), d.x());
  const int am = std::abs(m);
  const double k = std::sqrt((2.0 * l + 1.0) / (4.0 * M_PI) * std::tgamma(l - am + 1.0) / std::tgamma(l + am + 1.0));
  const double p = AssociatedLegendre(l, am, std::cos(theta));
  if (m == 0) return k * p;
  return std::sqrt(2.0) * k * p * (m > 0 ? std::cos(m * phi) : std::sin(am * phi));
}

TEST(SphericalHarmonics, OrthonormalByQuadrature) {
  // Gauss-Legendre in cos(theta) x uniform in phi integrates these
  // polynomials of degree <= 6 exactly.
  std::vector<double> nodes;
  std::vector<double> weights;
  GaussLegendre(16, nodes, weights);
  const int n_phi = 32;
  Eigen::Matrix<double, kCount, kCount> gram = Eigen::Matrix<double, kCount, kCount>::Zero();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const double z = nodes[i];
    const double r = std::sqrt(1.0 - z * z);
    for (int j = 0; j < n_phi; ++j) {
      const double phi = 2.0 * M_PI * j / n_phi;
      const Eigen::Vector3d d(r * std::cos(phi), r * std::sin(phi), z);
      const auto y = ShBasis<kMaxShDegree>(d);
      gram += weights[i] * (2.0 * M_PI / n_phi) * y * y.transpose();
    }
  }
  EXPECT_LT((gram - Eigen::Matrix<double, kCount, kCount>::Identity()).cwiseAbs().maxCoeff(), 1e-6) << gram;
}

TEST(SphericalHarmonics, MatchesAssociatedLegendreReference) {
  std::mt19937 rng(42);
  for (int sample = 0; sample < 1000; ++sample) {
    const Eigen::Vector3d d = RandomUnitVector(rng);
    const auto y = ShBasis<kMaxShDegree>(d);
    for (int l = 0; l <= kMaxShDegree; ++l) {
      for (int m = -l; m <= l; ++m) {
        ASSERT_NEAR(y[l * l + l + m], ReferenceSh(l, m, d), 1e-12) << "l=" << l << " m=" << m << " d=" << d.transpose();
      }
    }
  }
}

TEST(SphericalHarmonics, LowerDegreesArePrefixes) {
  const Eigen::Vector3d d = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  const auto y3 = ShBasis<3>(d);
  EXPECT_EQ(ShBasis<0>(d), y3.head<1>());
  EXPECT_EQ(ShBasis<1>(d), y3.head<4>());
  EXPECT_EQ(ShBasis<2>(d), y3.head<9>());
  for (int degree = 0; degree <= kMaxShDegree; ++degree) {
    double basis[kCount];
    EvaluateShBasis(degree, d, basis);
    for (int i = 0; i < ShCoefficientCount(degree); ++i) EXPECT_EQ(basis[i], y3[i]);
  }
}

TEST(SphericalHarmonics, EvaluateIsDotProduct) {
  std::mt19937 rng(1);
  std::normal_distribution<double> normal;
  Eigen::Matrix<double, kCount, 1> c;
  for (int i = 0; i < kCount; ++i) c[i] = normal(rng);
  const Eigen::Vector3d d = RandomUnitVector(rng);
  EXPECT_NEAR(EvaluateSh<3>(c.data(), d), c.dot(ShBasis<3>(d)), 1e-14);
  EXPECT_NEAR(EvaluateSh(2, c.data(), d), c.head<9>().dot(ShBasis<2>(d)), 1e-14);
}

TEST(SphericalHarmonics, RejectsUnknownDegree) {
  double basis[kCount];
  EXPECT_THROW(EvaluateShBasis(4, Eigen::Vector3d(1, 0, 0), basis), std::invalid_argument);
  EXPECT_THROW(EvaluateShBasis(-1, Eigen::Vector3d(1, 0, 0), basis), std::invalid_argument);
  const double coefficients[kCount] = {};
  EXPECT_THROW(EvaluateSh(4, coefficients, Eigen::Vector3d(1, 0, 0)), std::invalid_argument);
}

TEST(SphericalHarmonics, JetDerivativesMatchNumeric) {
  using Jet3 = ceres::Jet<double, 3>;
  std::mt19937 rng(9);
  for (int sample = 0; sample < 50; ++sample) {
    const Eigen::Vector3d d = RandomUnitVector(rng);
    Eigen::Matrix<Jet3, 3, 1> d_jet;
    for (int i = 0; i < 3; ++i) d_jet[i] = Jet3(d[i], i);
    const auto y_jet = ShBasis<kMaxShDegree>(d_jet);
    Eigen::Matrix<double, kCount, 3> analytic;
    for (int i = 0; i < kCount; ++i) analytic.row(i) = y_jet[i].v.transpose();
    const Eigen::MatrixXd numeric = NumericJacobian(
        [](const Eigen::VectorXd& x) { return Eigen::VectorXd(ShBasis<kMaxShDegree>(Eigen::Vector3d(x))); }, d);
    EXPECT_LT((analytic - numeric).norm(), 1e-8);
  }
}

// The analytic gradient, basis function by basis function (unit
// coefficient vectors), against the Jets' derivatives of EvaluateShBasis.
TEST(SphericalHarmonics, AnalyticGradientMatchesJets) {
  using Jet3 = ceres::Jet<double, 3>;
  std::mt19937 rng(10);
  for (int sample = 0; sample < 200; ++sample) {
    const Eigen::Vector3d d = RandomUnitVector(rng);
    Eigen::Matrix<Jet3, 3, 1> d_jet;
    for (int i = 0; i < 3; ++i) d_jet[i] = Jet3(d[i], i);
    const auto y_jet = ShBasis<kMaxShDegree>(d_jet);
    for (int i = 0; i < kCount; ++i) {
      std::array<double, kCount> unit{};
      unit[i] = 1.0;
      Eigen::Vector3d gradient;
      const double value = EvaluateShWithGradient<kMaxShDegree>(unit.data(), d, gradient);
      ASSERT_NEAR(value, y_jet[i].a, 1e-12) << i;
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(gradient[k], y_jet[i].v[k], 1e-12) << i << " " << k;
    }
  }
}

// c . Y(d) and its gradient in one pass, for every degree, against the
// dot product with the basis and a central-difference gradient of it.
TEST(SphericalHarmonics, ValueWithGradientMatchesDotProductAndNumeric) {
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  for (int degree = 0; degree <= kMaxShDegree; ++degree) {
    for (int sample = 0; sample < 20; ++sample) {
      Eigen::Matrix<double, kCount, 1> c;
      for (int i = 0; i < kCount; ++i) c[i] = normal(rng);
      const Eigen::Vector3d d = RandomUnitVector(rng);
      Eigen::Vector3d gradient;
      const double value = EvaluateShWithGradient(degree, c.data(), d, gradient);
      double basis_values[kCount];
      EvaluateShBasis(degree, d, basis_values);
      double dot = 0.0;
      for (int i = 0; i < ShCoefficientCount(degree); ++i) dot += c[i] * basis_values[i];
      EXPECT_NEAR(value, dot, 1e-13) << degree;
      EXPECT_NEAR(EvaluateSh(degree, c.data(), d), dot, 1e-13) << degree;
      const Eigen::MatrixXd numeric = NumericJacobian(
          [&](const Eigen::VectorXd& x) {
            return Eigen::VectorXd::Constant(1, EvaluateSh(degree, c.data(), Eigen::Vector3d(x)));
          },
          d);
      EXPECT_LT((gradient.transpose() - numeric).norm(), 1e-7) << degree;
      if (degree == 0) {
        EXPECT_EQ(gradient, Eigen::Vector3d::Zero());
      }
      // The basis it can hand out on the way (joint refinement's dr/dc).
      double basis_out[kCount], basis[kCount];
      EvaluateShWithGradient(degree, c.data(), d, gradient, basis_out);
      EvaluateShBasis(degree, d, basis);
      for (int i = 0; i < ShCoefficientCount(degree); ++i) EXPECT_EQ(basis_out[i], basis[i]) << degree << " " << i;
    }
  }
  Eigen::Vector3d gradient;
  EXPECT_THROW(EvaluateShWithGradient(4, std::array<double, kCount>{}.data(), Eigen::Vector3d(1, 0, 0), gradient),
               std::invalid_argument);
}

}  // namespace
}  // namespace radargauss
