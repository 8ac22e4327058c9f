// SPDX-License-Identifier: BSD-3-Clause
// A short tour of the core API: poses, spherical harmonics, trajectories.
#include <cstdio>

#include "radargauss/lie/se3.hpp"
#include "radargauss/core/sh.hpp"
#include "radargauss/core/trajectory.hpp"

int main() {
  using namespace radargauss;
  // A radar pose T_world_radar: 30 deg yaw, 2 m forward.
  Eigen::Matrix<double, 6, 1> xi;
  xi << 2.0, 0.0, 0.0, 0.0, 0.0, 30.0 * M_PI / 180.0;
  const SE3d T_world_radar = SE3d::Exp(xi);
  const Eigen::Vector3d p_radar(10.0, 1.0, 0.5);
  const Eigen::Vector3d q_world = T_world_radar * p_radar;
  std::printf("radar point (%.2f %.2f %.2f) -> world (%.3f %.3f %.3f)\n", p_radar.x(), p_radar.y(), p_radar.z(),
              q_world.x(), q_world.y(), q_world.z());

  // The degree-3 real SH basis (3DGS convention) in the direction facing the radar.
  const Eigen::Vector3d d = Eigen::Vector3d(-1.0, 0.2, 0.1).normalized();
  const auto basis = ShBasis<3>(d);
  std::printf("Y_0..Y_15(d):");
  for (int i = 0; i < basis.size(); ++i) std::printf(" %.3f", basis[i]);
  std::printf("\n");

  // Interpolating a two-sample trajectory halfway.
  Trajectory trajectory;
  trajectory.Append(0.0, SE3d());
  trajectory.Append(1.0, T_world_radar);
  const SE3d half = *trajectory.Interpolate(0.5);
  std::printf("halfway: t = (%.3f %.3f %.3f), yaw = %.2f deg\n", half.translation().x(), half.translation().y(),
              half.translation().z(), half.rotation().Log().z() * 180.0 / M_PI);
  return 0;
}
