// SPDX-License-Identifier: BSD-3-Clause
// Shared fixtures of the map tests: Gaussians planted with known means and
// covariances, and points drawn from them.
#pragma once

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>

#include "radargauss/core/error.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/map_cloud.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "temp_dir.hpp"
#include "test_util.hpp"

namespace radargauss {

using testing::RandomUnitVector;

struct Planted {
  std::vector<Gaussian> gaussians;
  std::vector<Eigen::Vector3d> points;
};

// Well-separated anisotropic Gaussians on a 6 m grid, `per` samples each.
inline Planted PlantGaussians(int per, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.15, 0.45);
  Planted planted;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      Gaussian g;
      g.mean = Eigen::Vector3d(6.0 * i, 6.0 * j, 1.0 + 0.5 * i);
      const Eigen::Matrix3d axes = SO3d::Exp(RandomUnitVector(rng)).Matrix();
      const Eigen::Vector3d stds(uniform(rng), uniform(rng), uniform(rng));
      g.covariance = ClampCovariance(axes * stds.array().square().matrix().asDiagonal() * axes.transpose(), 0.0);
      const Eigen::Matrix3d root = axes * stds.asDiagonal();
      for (int k = 0; k < per; ++k) {
        planted.points.push_back(g.mean + root * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
      }
      planted.gaussians.push_back(g);
    }
  }
  return planted;
}

}  // namespace radargauss
