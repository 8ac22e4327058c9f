// SPDX-License-Identifier: BSD-3-Clause
// What sets an inertial window up (solvers/inertial_window.hpp): its
// options and the first state from gravity and the radar's first pose.
#include "radargauss/solvers/inertial_window.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "radargauss/core/error.hpp"
#include "radargauss/io/imu.hpp"
#include "radargauss/core/names.hpp"
#include "radargauss/residuals/radar_inertial_residuals.hpp"

namespace radargauss {

namespace {

const NamedValue<WindowSolver> kWindowSolverNames[] = {{WindowSolver::kCeresLm, "ceres-lm"},
                                                       {WindowSolver::kCeresDogleg, "ceres-dogleg"},
                                                       {WindowSolver::kGaussNewton, "gn"}};

}  // namespace

std::string ToString(WindowSolver solver) { return NameOf(kWindowSolverNames, solver); }
WindowSolver WindowSolverFromString(const std::string& name) {
  return ValueNamed(kWindowSolverNames, name, "window solver");
}
std::vector<std::string> WindowSolverNames() { return NamesOf(kWindowSolverNames); }

const OptionTable<InertialWindowOptions>& InertialWindowOptionTable() {
  using O = InertialWindowOptions;
  static const OptionTable<O> table = [] {
    OptionTable<O> t = {
        RADARGAUSS_OPTION(O, "window_size", size).In(2, 1000).Help("IMU states the sliding window keeps"),
        RADARGAUSS_CHOICE(O, "window_solver", solver, WindowSolverNames(), WindowSolverFromString)
            .Help("the window's solver: ceres-lm, ceres-dogleg or gn (own Gauss-Newton)"),
        RADARGAUSS_OPTION(O, "window_iterations", max_iterations).In(1, 1000).Help("iterations per solve"),
        RADARGAUSS_OPTION(O, "window_marginalize", marginalize)
            .Help("a leaving state becomes a prior (Schur complement); false: it is dropped"),
        RADARGAUSS_OPTION(O, "window_gyro_bias_prior", gyro_bias_prior)
            .Above(0.0)
            .Unit("rad/s")
            .Help("std of the first state's gyro bias about zero"),
        RADARGAUSS_OPTION(O, "window_accel_bias_prior", accel_bias_prior)
            .Above(0.0)
            .Unit("m/s^2")
            .Help("std of the first state's accelerometer bias about zero"),
        RADARGAUSS_OPTION(O, "window_velocity_prior", velocity_prior)
            .Above(0.0)
            .Unit("m/s")
            .Help("std of the first state's velocity about the start's"),
        RADARGAUSS_OPTION(O, "window_extrinsic_rotation_prior", extrinsic_rotation_prior_deg)
            .In(0.0, 180.0)
            .Above(0.0)
            .Unit("deg")
            .Help("std of an estimated radar-IMU rotation about its start"),
        RADARGAUSS_OPTION(O, "window_extrinsic_translation_prior", extrinsic_translation_prior)
            .In(0.0, 1000.0)
            .Unit("m")
            .Help("std of an estimated radar-IMU translation about its start (0: none)"),
        RADARGAUSS_OPTION(O, "window_clock_offset_prior", clock_offset_prior)
            .In(0.0, 1.0)
            .Above(0.0)
            .Unit("s")
            .Help("std of an estimated clock offset about its start"),
        RADARGAUSS_OPTION(O, "estimate_tilt", estimate_tilt)
            .Help("estimate the roll and pitch of the matcher's world against gravity"),
        RADARGAUSS_OPTION(O, "estimate_extrinsic_rotation", estimate_extrinsic_rotation)
            .Help("estimate the radar-IMU rotation online"),
        RADARGAUSS_OPTION(O, "estimate_extrinsic_translation", estimate_extrinsic_translation)
            .Help("estimate the radar-IMU translation online (where the motion excites it)"),
        RADARGAUSS_OPTION(O, "imu_clock_offset", clock_offset)
            .In(-0.1, 0.1)
            .Unit("s")
            .Help("the IMU's stamps minus the radar's clock (the start when estimated)"),
        RADARGAUSS_OPTION(O, "estimate_clock_offset", estimate_clock_offset)
            .Help("estimate the IMU-radar clock offset online"),
        RADARGAUSS_OPTION(O, "calibration_gate", calibration_gate)
            .Help("estimate a calibration only along the directions the motion observes, hold the rest"),
        RADARGAUSS_OPTION(O, "observed_rotation_std", observed_rotation_std_deg)
            .In(1e-6, 90.0)
            .Unit("deg")
            .Help("the extrinsic rotation's data std below which a direction counts as observed"),
        RADARGAUSS_OPTION(O, "observed_translation_std", observed_translation_std)
            .In(1e-6, 100.0)
            .Unit("m")
            .Help("the extrinsic translation's data std below which a direction counts as observed"),
        RADARGAUSS_OPTION(O, "observed_clock_std", observed_clock_std)
            .In(1e-6, 1.0)
            .Unit("s")
            .Help("the clock offset's data std below which it counts as observed"),
        RADARGAUSS_OPTION(O, "observed_elevation_bias_std", observed_elevation_bias_std_deg)
            .In(1e-6, 90.0)
            .Unit("deg")
            .Help("the elevation bias's data std below which it counts as observed"),
        RADARGAUSS_OPTION(O, "vehicle_motion_std", vehicle_motion_std)
            .AtLeast(0.0)
            .Unit("m/s")
            .Help("a ground vehicle's IMU, aligned with it: std of its lateral and vertical velocity (0: off)"),
    };
    AppendNested(
        t, ImuNoiseOptionTable(), +[](O & o) -> auto& { return o.noise; }, "noise", "imu_");
    return t;
  }();
  return table;
}

// A = Ry(pitch) Rx(roll) takes gravity's up (0, 0, 1) to (cos r sin p, -sin r, cos r cos p).
InertialStart StartFromGravity(const std::vector<ImuSample>& samples, double stamp, const SE3d& world_from_radar,
                               const Eigen::Vector3d& radar_velocity, const SE3d& radar_from_imu, double span,
                               double clock_offset) {
  Eigen::Vector3d force = Eigen::Vector3d::Zero(), rate = Eigen::Vector3d::Zero();
  int count = 0;
  for (const ImuSample& sample : samples) {
    if (std::abs(sample.stamp - clock_offset - stamp) > 0.5 * span) continue;
    force += sample.specific_force;
    rate += sample.angular_velocity;
    ++count;
  }
  if (count == 0) throw DataError("no IMU sample within " + std::to_string(0.5 * span) + " s of the first scan");
  force /= count;
  rate /= count;
  const SE3d world_from_imu = world_from_radar * radar_from_imu;
  const Eigen::Vector3d up = world_from_imu.rotation() * force.normalized();  // in the matcher's world
  InertialStart start;
  start.tilt = Eigen::Vector2d(-std::asin(std::clamp(up.y(), -1.0, 1.0)), std::atan2(up.x(), up.z()));
  const SO3d tilt_inverse = TiltRotation(start.tilt.data()).Inverse();
  start.state.stamp = stamp;
  start.state.pose = SE3d(tilt_inverse, Eigen::Vector3d::Zero()) * world_from_imu;
  // R^T v = R_e v_radar - w x t_e (residuals/radar_inertial_residuals.hpp), with T_imu_radar = (R_e, t_e).
  const SE3d imu_from_radar = radar_from_imu.Inverse();
  const Eigen::Vector3d imu_velocity =
      imu_from_radar.rotation() * radar_velocity - rate.cross(imu_from_radar.translation());
  start.state.velocity = start.state.pose.rotation() * imu_velocity;
  return start;
}

}  // namespace radargauss
