// SPDX-License-Identifier: BSD-3-Clause
// Radar odometry and the option tables in Python.
#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "option_fields.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/imu.hpp"
#include "radargauss/odometry/radar_inertial.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/slam/radar_slam.hpp"
#include "radargauss/solvers/joint_refinement.hpp"
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
  d["map_update_ms"] = s.map_update_ms;
  d["information"] = MatrixToArray<6, 6>(s.information);
  d["velocity_information"] = MatrixToArray<6, 6>(s.velocity_information);
  d["rotation_information"] = MatrixToArray<6, 6>(s.rotation_information);
  return d;
}

const char* OdometryDoc() {
  static const std::string doc =
      "Radar odometry on a map it builds as it goes (docs/design/odometry.md, \"Odometry\"): register scans in time "
      "order. Threads may share one: its calls take turns.\n\nParameters\n----------\n"
      "**options\n    any of the keywords below (odometry_options() gives them all with their values)\n" +
      ParametersDoc(OdometryOptionTable());
  return doc.c_str();
}

}  // namespace

OdometryOptions OdometryOptionsFrom(const py::kwargs& kwargs) {
  const OdometryOptions options = OptionsFrom(OdometryOptionTable(), kwargs);
  ValidateOptions(options);  // std::invalid_argument: ValueError
  return options;
}

// An (N, 7) array [stamp wx wy wz ax ay az] (s, rad/s, m/s^2, the IMU's frame).
std::vector<ImuSample> ImuFromArray(const py::handle& value) {
  const Array imu = CheckedArray(value, {-1, 7}, "imu");
  const auto rows = imu.unchecked<2>();
  std::vector<ImuSample> samples(std::size_t(rows.shape(0)));
  for (py::ssize_t i = 0; i < rows.shape(0); ++i) {
    samples[std::size_t(i)] = {rows(i, 0), Eigen::Vector3d(rows(i, 1), rows(i, 2), rows(i, 3)),
                               Eigen::Vector3d(rows(i, 4), rows(i, 5), rows(i, 6))};
    for (int c = 0; c < 7; ++c) {
      if (!std::isfinite(rows(i, c))) throw py::value_error("imu: row " + std::to_string(i) + " is not finite");
    }
  }
  return samples;
}

py::object StateToDict(const std::optional<InertialState>& s) {
  if (!s) return py::none();
  py::dict d;
  d["stamp"] = s->stamp;
  d["pose"] = PoseToMatrix(s->pose);
  d["velocity"] = MatrixToArray<3, 1>(s->velocity);
  d["gyro_bias"] = MatrixToArray<3, 1>(s->bias.gyro);
  d["accel_bias"] = MatrixToArray<3, 1>(s->bias.accel);
  return std::move(d);
}

// The keywords split between the odometry's table and the window's.
std::pair<OdometryOptions, RadarInertialOptions> InertialOptionsFrom(const py::kwargs& kwargs) {
  py::kwargs odometry, inertial;
  for (const auto& [key, value] : kwargs) {
    const std::string keyword = py::str(key);
    (FindOption(RadarInertialOptionTable(), keyword) ? inertial : odometry)[key] = value;
  }
  const RadarInertialOptions options = OptionsFrom(RadarInertialOptionTable(), inertial);
  CheckOptions(RadarInertialOptionTable(), options);
  return {OdometryOptionsFrom(odometry), options};
}

namespace {

const char* InertialDoc() {
  static const std::string doc =
      "Radar-inertial odometry (docs/design/odometry.md, \"Radar-inertial odometry\"): the radar odometry with "
      "the IMU's motion model named by imu_fusion: 'window', a sliding window of IMU states, or 'gyro', the gyro's "
      "rates for the prediction only. Threads may share one: its calls take turns.\n\nParameters\n----------\n"
      "imu : array (N, 7)\n    [stamp wx wy wz ax ay az] per sample, time order, on the scans' clock (s, rad/s, "
      "m/s^2, the IMU's frame)\nradar_from_imu : array (4, 4) or [x y z qx qy qz qw], default identity\n    "
      "T_radar_imu, the IMU's frame in the radar's\n**options\n    any keyword of RadarOdometry and these "
      "(option_fields('radar_inertial')):\n" +
      ParametersDoc(RadarInertialOptionTable());
  return doc.c_str();
}

// Its own Python type: the radar odometry with the IMU's motion model.
struct LockedInertial : Locked<RadarOdometry> {
  using Locked<RadarOdometry>::Locked;
};

void BindInertialOdometry(py::module_& m) {
  py::class_<LockedInertial>(m, "RadarInertialOdometry", InertialDoc())
      .def(py::init([](const py::handle& imu, const py::object& radar_from_imu, const py::kwargs& kwargs) {
             const auto [odometry, inertial] = InertialOptionsFrom(kwargs);
             const SE3d extrinsic =
                 radar_from_imu.is_none() ? SE3d() : PoseFromPython(radar_from_imu, "radar_from_imu");
             std::vector<ImuSample> samples = ImuFromArray(imu);
             if (samples.empty()) throw DataError("the IMU has no sample");
             return std::make_unique<LockedInertial>(
                 std::make_unique<RadarOdometry>(odometry, MakeMotionModel(inertial, extrinsic, std::move(samples))));
           }),
           py::arg("imu"), py::arg("radar_from_imu") = py::none())
      .def(
          "register",
          [](LockedInertial& odometry, const RadarScan& scan) {
            const auto [step, state] = odometry.With([&](RadarOdometry& o) {
              o.Register(scan);
              const OdometryStep s = o.steps().back();  // its map fields complete
              const InertialMotion* window = InertialMotionOf(o);
              return std::make_pair(s, window ? window->states().back() : std::nullopt);
            });
            py::dict d = StepToDict(step);
            d["inertial"] = StateToDict(state);
            return d;
          },
          py::arg("scan"),
          "Adds the next scan; returns RadarOdometry.register's dict with 'inertial': the window's newest state "
          "(pose, velocity, gyro_bias, accel_bias), or None before the window started and with imu_fusion='gyro'")
      .def(
          "trajectory",
          [](LockedInertial& odometry) {
            return TrajectoryToArrays(odometry.With([](RadarOdometry& o) { return o.trajectory(); }));
          },
          "(stamps (N,), poses (N, 7)) of the radar so far, in the matcher's world")
      .def(
          "calibration",
          [](LockedInertial& odometry) {
            const auto [tilt, offset, radar_from_imu, u] = odometry.With([](RadarOdometry& o) {
              const InertialMotion* window = InertialMotionOf(o);
              if (!window) throw std::invalid_argument("calibration: imu_fusion='gyro' has no window");
              const InertialWindow& w = window->window();
              return std::make_tuple(Eigen::Vector2d(w.tilt()), w.clock_offset(), w.radar_from_imu(),
                                     w.size() > 0 ? w.Uncertainty() : WindowUncertainty{});
            });
            py::dict d;
            d["tilt"] = MatrixToArray<2, 1>(tilt);
            d["tilt_std"] = MatrixToArray<2, 1>(u.tilt);
            d["clock_offset"] = offset;
            d["clock_offset_std"] = u.clock_offset;
            d["radar_from_imu"] = PoseToMatrix(radar_from_imu);
            d["gyro_bias_std"] = MatrixToArray<3, 1>(u.gyro_bias);
            d["accel_bias_std"] = MatrixToArray<3, 1>(u.accel_bias);
            return d;
          },
          "The window's tilt (rad, roll and pitch of the matcher's world against gravity), clock offset (s), "
          "T_radar_imu, and the standard deviations of those estimated and of the newest biases")
      .def(
          "imu_dropped",
          [](LockedInertial& odometry) {
            const ImuScreening screening = odometry.With([](RadarOdometry& o) { return o.motion().screening(); });
            py::dict d;
            d["beyond_range"] = screening.beyond_range;
            d["spikes"] = screening.spikes;
            return d;
          },
          "The IMU samples dropped before the window saw them: 'beyond_range' (imu_gyro_range, imu_accel_range) "
          "and isolated 'spikes'")
      .def("__len__",
           [](LockedInertial& odometry) { return odometry.With([](RadarOdometry& o) { return o.steps().size(); }); });
}

void BindOptionFunctions(py::module_& m);

}  // namespace

void BindOdometry(py::module_& m) {
  BindInertialOdometry(m);
  m.def(
      "read_imu",
      [](const std::string& path) {
        const std::vector<ImuSample> samples = ReadImuFile(path);
        Array out = NewArray({py::ssize_t(samples.size()), 7});
        auto rows = out.mutable_unchecked<2>();
        for (std::size_t i = 0; i < samples.size(); ++i) {
          const ImuSample& s = samples[i];
          const double row[7] = {s.stamp,
                                 s.angular_velocity.x(),
                                 s.angular_velocity.y(),
                                 s.angular_velocity.z(),
                                 s.specific_force.x(),
                                 s.specific_force.y(),
                                 s.specific_force.z()};
          for (int c = 0; c < 7; ++c) rows(py::ssize_t(i), c) = row[c];
        }
        return out;
      },
      py::arg("path"), "An IMU file (lines 'stamp wx wy wz ax ay az') as an (N, 7) array; DataError names the line");

  using LockedOdometry = Locked<RadarOdometry>;
  py::class_<LockedOdometry>(m, "RadarOdometry", OdometryDoc())
      .def(py::init([](const py::kwargs& kwargs) {
        return std::make_unique<LockedOdometry>(std::make_unique<RadarOdometry>(OdometryOptionsFrom(kwargs)));
      }))
      .def(
          "register",
          [](LockedOdometry& odometry, const RadarScan& scan) {
            return StepToDict(odometry.With([&](RadarOdometry& o) {
              o.Register(scan);
              return o.steps().back();  // its map fields complete: the map update behind it finished
            }));
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
  BindOptionFunctions(m);
}

namespace {

// The option dicts and option_fields: the tables as Python sees them.
void BindOptionFunctions(py::module_& m) {
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
        if (kind == "matching_map") return FieldsToList(MatchingMapOptionTable());
        if (kind == "joint_refinement") return FieldsToList(JointRefinementOptionTable());
        throw py::value_error(
            "option_fields takes 'match', 'odometry', 'slam', 'relocalization', 'radar_inertial', 'matching_map' or "
            "'joint_refinement', not '" +
            kind + "'");
      },
      py::arg("kind"),
      "The keywords of match, RadarOdometry, RadarSlam, Relocalizer or the radar-inertial window ('match', "
      "'odometry', 'slam', 'relocalization', 'radar_inertial'), and the rows of the matching map's and the joint "
      "refinement's tables that localize and refine read ('matching_map', 'joint_refinement'): one dict per option "
      "with its keyword, the C++ member it sets (path), type, doc, default, group, unit and range.");
}

}  // namespace

}  // namespace radargauss::python
