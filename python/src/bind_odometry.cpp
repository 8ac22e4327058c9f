// SPDX-License-Identifier: BSD-3-Clause
// Radar odometry and the option tables in Python.
#include <pybind11/stl.h>

#include <string>

#include "bindings.hpp"
#include "option_fields.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/slam/radar_slam.hpp"
#include "radargauss/slam/relocalization.hpp"

namespace radargauss::python {

namespace {

py::dict StepToDict(const OdometryStep& s) {
  py::dict d;
  d["stamp"] = s.stamp;
  d["pose"] = PoseToMatrix(s.pose);
  d["points"] = s.points;
  d["static_points"] = s.static_points;
  d["velocity_measured"] = s.velocity_measured;
  d["standstill"] = s.standstill;
  d["gyro"] = s.gyro;
  d["velocity"] = MatrixToArray<3, 1>(s.velocity);
  d["velocity_covariance"] = MatrixToArray<3, 3>(s.velocity_covariance);
  d["matched"] = s.matched;
  d["iterations"] = s.iterations;
  d["cost"] = s.final_cost;
  d["converged"] = s.converged;
  d["reason"] = s.reason;
  d["keyframe"] = s.keyframe;
  d["active_gaussians"] = s.active_gaussians;
  d["active_map_bytes"] = s.active_map_bytes;
  d["time_ms"] = s.time_ms;
  d["information"] = MatrixToArray<6, 6>(s.information);
  d["velocity_information"] = MatrixToArray<6, 6>(s.velocity_information);
  d["rotation_information"] = MatrixToArray<6, 6>(s.rotation_information);
  return d;
}

const char* OdometryDoc() {
  static const std::string doc =
      "Radar odometry on a map it builds as it goes (docs/design.md, \"Odometry\"): register scans in time "
      "order. Threads may share one: its calls take turns.\n\nParameters\n----------\n"
      "**options\n    any of the keywords below (odometry_options() gives them all with their values)\n" +
      ParametersDoc(OdometryOptionTable());
  return doc.c_str();
}

OdometryOptions OdometryOptionsFrom(const py::kwargs& kwargs) {
  const OdometryOptions options = OptionsFrom(OdometryOptionTable(), kwargs);
  ValidateOptions(options);  // std::invalid_argument: ValueError
  return options;
}

}  // namespace

void BindOdometry(py::module_& m) {
  using LockedOdometry = Locked<RadarOdometry>;
  py::class_<LockedOdometry>(m, "RadarOdometry", OdometryDoc())
      .def(py::init([](const py::kwargs& kwargs) {
        return std::make_unique<LockedOdometry>(std::make_unique<RadarOdometry>(OdometryOptionsFrom(kwargs)));
      }))
      .def(
          "register",
          [](LockedOdometry& odometry, const RadarScan& scan) {
            return StepToDict(odometry.With([&](RadarOdometry& o) { return o.Register(scan); }));
          },
          py::arg("scan"),
          "Adds the next scan (stamps must increase); returns what happened to it as a dict: pose (4x4), "
          "velocity, matched, keyframe, reason, the information matrices, ...")
      .def(
          "trajectory",
          [](LockedOdometry& odometry) {
            return TrajectoryToArrays(odometry.With([](RadarOdometry& o) { return o.trajectory(); }));
          },
          "(stamps (N,), poses (N, 7)) so far")
      .def(
          "map",
          [](LockedOdometry& odometry) {
            return std::make_shared<PyMap>(odometry.With([](RadarOdometry& o) { return o.map().GlobalMap(); }));
          },
          "The map built so far, the Gaussians that left the active radius included")
      .def(
          "options",
          [](LockedOdometry& odometry) {
            return OptionsToDict(OdometryOptionTable(), odometry.With([](RadarOdometry& o) { return o.options(); }));
          },
          "Every option by keyword, as odometry_options gives them")
      .def_property_readonly(
          "matchers_made",
          [](LockedOdometry& odometry) { return odometry.With([](RadarOdometry& o) { return o.matchers_made(); }); },
          "Matchers made so far: one per version of the local map matched against")
      .def("__len__",
           [](LockedOdometry& odometry) { return odometry.With([](RadarOdometry& o) { return o.steps().size(); }); });
  m.def(
      "odometry_options",
      [](const py::kwargs& kwargs) { return OptionsToDict(OdometryOptionTable(), OdometryOptionsFrom(kwargs)); },
      "Every option of RadarOdometry, the given keywords set (checked), as a dict.");
  m.def(
      "slam_options",
      [](const py::kwargs& kwargs) {
        const SlamOptions options = OptionsFrom(SlamOptionTable(), kwargs);
        ValidateOptions(options);  // std::invalid_argument: ValueError
        return OptionsToDict(SlamOptionTable(), options);
      },
      "Every option of RadarSlam, the given keywords set (checked), as a dict.");
  m.def(
      "relocalization_options",
      [](const py::kwargs& kwargs) {
        const RelocalizationOptions options = OptionsFrom(RelocalizationOptionTable(), kwargs);
        ValidateOptions(options);  // std::invalid_argument: ValueError
        return OptionsToDict(RelocalizationOptionTable(), options);
      },
      "Every option of Relocalizer, the given keywords set (checked), as a dict.");
  m.def(
      "option_fields",
      [](const std::string& kind) {
        if (kind == "match") return FieldsToList(MatchOptionTable());
        if (kind == "odometry") return FieldsToList(OdometryOptionTable());
        if (kind == "slam") return FieldsToList(SlamOptionTable());
        if (kind == "relocalization") return FieldsToList(RelocalizationOptionTable());
        if (kind == "radar_inertial") return FieldsToList(RadarInertialOptionTable());
        throw py::value_error(
            "option_fields takes 'match', 'odometry', 'slam', 'relocalization' or 'radar_inertial', not '" + kind +
            "'");
      },
      py::arg("kind"),
      "The keywords of match, RadarOdometry, RadarSlam, Relocalizer or the radar-inertial window ('match', "
      "'odometry', 'slam', 'relocalization', 'radar_inertial'): one dict per option with its keyword, the C++ member "
      "it sets (path), type, doc, default, "
      "group, unit and range.");
}

}  // namespace radargauss::python
