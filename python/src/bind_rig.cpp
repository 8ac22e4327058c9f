// SPDX-License-Identifier: BSD-3-Clause
// Radar rigs in Python (docs/design/rig.md): the rig file, the rig's twist
// from its radars' Doppler, odometry on a rig and its calibration.
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "option_fields.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/rig_twist.hpp"
#include "radargauss/io/rig.hpp"
#include "radargauss/odometry/rig_calibration.hpp"
#include "radargauss/odometry/rig_odometry.hpp"

namespace radargauss::python {

namespace {

py::dict RadarToDict(const RigRadar& radar) {
  py::dict d;
  d["name"] = radar.name;
  d["sequence"] = radar.scans.sequence_dir;
  d["bag"] = radar.scans.bag;
  d["topic"] = radar.scans.topic;
  d["body_from_radar"] = PoseToMatrix(radar.body_from_radar);
  d["clock_offset"] = radar.clock_offset;
  return d;
}

py::dict TwistToDict(const RigTwist& twist) {
  py::dict d;
  d["success"] = twist.success;
  d["reason"] = twist.reason;
  d["velocity"] = MatrixToArray<3, 1>(twist.velocity);
  d["angular_velocity"] = MatrixToArray<3, 1>(twist.angular_velocity);
  d["covariance"] = MatrixToArray<6, 6>(twist.covariance);
  d["observed"] = MatrixToArray<6, 6>(twist.observed);
  d["rank"] = twist.rank;
  py::list inliers;
  for (const std::vector<bool>& radar : twist.inlier) inliers.append(py::cast(radar));
  d["inlier"] = inliers;
  return d;
}

py::dict CalibrationToDict(const RigCalibration& calibration) {
  py::list rig, radars;
  for (const RigRadar& radar : calibration.rig.radars) rig.append(RadarToDict(radar));
  for (const RadarCalibration& c : calibration.radars) {
    py::dict d;
    d["name"] = c.name;
    d["body_from_radar"] = PoseToMatrix(c.body_from_radar);
    d["clock_offset"] = c.clock_offset;
    d["rotation_std"] = MatrixToArray<3, 1>(c.rotation_std);
    d["translation_std"] = MatrixToArray<3, 1>(c.translation_std);
    d["clock_offset_std"] = c.clock_offset_std;
    d["scans"] = c.scans;
    d["doppler_points"] = c.doppler_points;
    d["map_points"] = c.map_points;
    radars.append(d);
  }
  py::dict out;
  out["rig"] = rig;
  out["radars"] = radars;
  return out;
}

// The keywords imu ((N, 7) samples) and body_from_imu (T_body_imu, default
// identity) as a rig's IMU, the window at its defaults; none without imu.
std::optional<RigImu> RigImuFrom(const py::object& imu, const py::object& body_from_imu) {
  if (imu.is_none()) {
    if (!body_from_imu.is_none()) throw py::value_error("body_from_imu needs imu");
    return std::nullopt;
  }
  RigImu rig_imu{
      ImuFromArray(imu), body_from_imu.is_none() ? SE3d() : PoseFromPython(body_from_imu, "body_from_imu"), {}};
  if (rig_imu.samples.empty()) throw DataError("the IMU has no sample");
  return rig_imu;
}

void BindRigRuns(py::module_& m) {
  m.def(
      "rig_odometry",
      [](const std::string& path, const py::object& imu, const py::object& body_from_imu, const py::kwargs& kwargs) {
        const auto [options, inertial] = InertialOptionsFrom(kwargs);
        std::optional<RigImu> rig_imu = RigImuFrom(imu, body_from_imu);
        const Rig rig = ReadRig(path);
        std::vector<SE3d> mountings;
        for (const RigRadar& radar : rig.radars) mountings.push_back(radar.body_from_radar);
        std::unique_ptr<MotionModel> motion;
        if (rig_imu) {
          motion = MakeRigMotionModel(inertial, mountings.front(), rig_imu->body_from_imu, std::move(rig_imu->samples));
        }
        RigOdometry odometry(mountings, options, std::move(motion));
        {
          py::gil_scoped_release release;
          ForEachRigScan(
              rig, [&](std::size_t radar, RadarScan& scan, const std::string&) { odometry.Register(radar, scan); });
          odometry.Finish();
        }
        py::dict out;
        out["trajectory"] = TrajectoryToArrays(odometry.trajectory());
        out["frame_radars"] = py::cast(odometry.frame_radars());
        out["velocity_measured"] = odometry.velocity_measured();
        out["rig_velocity_measured"] = odometry.rig_velocity_measured();
        if (const InertialMotion* window = InertialMotionOf(odometry.odometry())) {
          out["inertial_state"] = window->states().empty() ? py::none() : StateToDict(window->states().back());
        }
        if (const RigOnlineCalibration* calibration = odometry.frames().online_calibration()) {
          py::list calibrated;
          for (const RigRadar& radar : OnlineCalibratedRig(rig, odometry.frames()).radars) {
            calibrated.append(RadarToDict(radar));
          }
          Array stds = NewArray({py::ssize_t(calibration->radars()), 7});  // the reference's: zeros
          auto view = stds.mutable_unchecked<2>();
          for (std::size_t r = 0; r < calibration->radars(); ++r) {
            for (int k = 0; k < 7; ++k) view(py::ssize_t(r), k) = r == 0 ? 0.0 : calibration->std(r)(k);
          }
          out["rig"] = calibrated;
          out["calibration_std"] = stds;
          out["calibration_windows"] = calibration->windows();
        }
        return out;
      },
      py::arg("path"), py::arg("imu") = py::none(), py::arg("body_from_imu") = py::none(),
      "The body's odometry from a rig file's radars (docs/design/rig.md, \"Odometry on a rig\"), with an IMU "
      "on the body when given (\"An IMU on a rig\"). A dict: trajectory ((stamps (N,), poses (N, 7)) of "
      "T_world_body), frame_radars (each frame's radars), velocity_measured, rig_velocity_measured (frames); "
      "with the IMU's window, inertial_state (the newest state, in the first radar's frame; None before the "
      "window started).\n\nimu: array (N, 7) [stamp wx wy wz ax ay az] on the body's clock (s, rad/s, m/s^2, "
      "the IMU's frame); body_from_imu: (4, 4) or [x y z qx qy qz qw], T_body_imu, default identity.\n\n"
      "With rig_calibrate=True (the online calibration, docs/design/rig.md, \"Online calibration\"): rig (the "
      "radars as read_rig gives them, calibrated), calibration_std ((radars, 7): rotation rad, translation m, "
      "clock s; zeros for the reference) and calibration_windows.\n\n"
      "Keywords: RadarOdometry's (odometry_options) and RadarInertialOdometry's (option_fields('radar_inertial'))");
  m.def(
      "calibrate_rig",
      [](const std::string& path, const py::object& imu, const py::object& body_from_imu, const py::kwargs& kwargs) {
        RigCalibrationOptions options = OptionsFrom(RigCalibrationOptionTable(), kwargs);
        ValidateOptions(options);
        const std::optional<RigImu> rig_imu = RigImuFrom(imu, body_from_imu);
        const Rig rig = ReadRig(path);
        const std::vector<std::vector<RadarScan>> scans = LoadRigScans(rig);
        RigCalibration calibration;
        {
          py::gil_scoped_release release;
          calibration = CalibrateRig(rig, scans, options, rig_imu);
        }
        py::dict out = CalibrationToDict(calibration);
        out["gyro"] = calibration.gyro;
        return out;
      },
      py::arg("path"), py::arg("imu") = py::none(), py::arg("body_from_imu") = py::none(),
      ("Each radar's extrinsic and clock offset of a rig file against its first radar, over its drive "
       "(docs/design/rig.md, \"Calibration of a rig\"). A dict: rig (the radars as read_rig gives them, "
       "calibrated) and radars (per radar: name, body_from_radar, clock_offset, rotation_std (rad), "
       "translation_std (m), clock_offset_std (s), inf where unobserved; scans, doppler_points, map_points); "
       "gyro: whether the reference's rates came from the IMU. imu: (N, 7) [stamp wx wy wz ax ay az] on the body's "
       "clock, body_from_imu: T_body_imu (default identity): the reference's odometry with the IMU's window and its "
       "rates from the gyro."
       "\n\nKeywords:\n" +
       ParametersDoc(RigCalibrationOptionTable()))
          .c_str());
}

}  // namespace

void BindRig(py::module_& m) {
  BindRigRuns(m);
  m.def(
      "read_rig",
      [](const std::string& path) {
        py::list radars;
        for (const RigRadar& radar : ReadRig(path).radars) radars.append(RadarToDict(radar));
        return radars;
      },
      py::arg("path"),
      "The radars of a rig file, each a dict: name, sequence (a folder) or bag and topic, body_from_radar "
      "(4x4 T_body_radar), clock_offset (s: the radar's stamps minus the body's clock).");
  m.def(
      "estimate_rig_twist",
      [](const std::vector<RadarScan>& scans, const py::handle& body_from_radar, const py::kwargs& kwargs) {
        std::vector<SE3d> mountings;
        for (const py::handle pose : py::iter(body_from_radar)) {
          mountings.push_back(PoseFromPython(pose, "body_from_radar[" + std::to_string(mountings.size()) + "]"));
        }
        if (mountings.size() != scans.size()) {
          throw py::value_error("one body_from_radar per scan: " + std::to_string(scans.size()) + " scans, " +
                                std::to_string(mountings.size()) + " mountings");
        }
        RigTwistOptions options;
        options.doppler = OptionsFrom(EgoVelocityOptionTable(), kwargs);
        std::vector<RigScan> rig;
        for (std::size_t r = 0; r < scans.size(); ++r) rig.push_back({&scans[r], mountings[r]});
        RigTwist twist;
        {
          py::gil_scoped_release release;
          twist = EstimateRigTwist(rig, options);
        }
        return TwistToDict(twist);
      },
      py::arg("scans"), py::arg("body_from_radar"),
      ("The body's velocity and angular velocity (body frame) from the Doppler of several radars' scans taken "
       "together, each radar at its body_from_radar (4x4 or [x y z qx qy qz qw]). A dict: success, reason, "
       "velocity, angular_velocity, covariance (6x6 of [v; w]), observed (the projector onto the observed "
       "directions), rank, inlier (per radar, per point).\n\nKeywords: the Doppler filter's\n" +
       ParametersDoc(EgoVelocityOptionTable()))
          .c_str());
}

}  // namespace radargauss::python
