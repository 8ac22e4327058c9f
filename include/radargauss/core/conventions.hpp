// SPDX-License-Identifier: BSD-3-Clause
// radargauss conventions: the single place where each one is stated
// (docs/design.md, "Conventions"). Every other file refers here instead of restating.
#pragma once

#include <cmath>

namespace radargauss {

// Frames. The radar frame is x forward, y left, z up. A pose
// T_world_radar = (R, t) maps a radar-frame point p to the world frame:
// q = R p + t.
//
// Rotations. Unit quaternions stored x y z w (the Eigen and Ceres memory
// order). SO3 and SE3 use the RIGHT perturbation: X (+) d = X * Exp(d).
//
// SE3 tangent order. [rho; phi]: translation part first, rotation second.
// The solvers' 6-vector update is [dt (world frame); dphi (radar frame)].
inline constexpr int kTranslationOffset = 0;  // rho (or dt) in a 6-vector
inline constexpr int kRotationOffset = 3;     // phi (or dphi) in a 6-vector

// Doppler. Radial velocity of the target relative to the sensor, positive
// when receding: v_d = u . (v_target - v_sensor), u = p / |p|. A static
// point gives v_d = -u . v_sensor.
//
// Units. RCS in dBsm, time in seconds (double), lengths in metres, angles in
// radians inside the library (degrees only in user-facing tables and flags).
inline constexpr double kRadiansPerDegree = M_PI / 180.0;
inline constexpr double kDegreesPerRadian = 180.0 / M_PI;

}  // namespace radargauss
