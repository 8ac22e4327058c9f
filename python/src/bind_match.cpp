// SPDX-License-Identifier: BSD-3-Clause
// Scan matching, odometry and trajectory evaluation in Python.
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "bindings.hpp"
#include "radargauss/evaluation.hpp"
#include "radargauss/experiment.hpp"
#include "radargauss/names.hpp"
#include "radargauss/odometry/radar_odometry.hpp"
#include "radargauss/radargauss.hpp"

namespace radargauss::python {

namespace {

// The options of one match, by the names `radargauss localize` takes.
MatchOptions MatchOptionsFrom(double w_rcs, const std::string& solver, const std::string& loss, double loss_scale,
                              const std::string& rcs_loss, double rcs_loss_scale) {
  if (!(w_rcs >= 0.0 && w_rcs <= 1.0)) throw py::value_error("w_rcs must be in [0, 1]");
  if (!(loss_scale > 0.0) || !(rcs_loss_scale > 0.0) || !std::isfinite(loss_scale) || !std::isfinite(rcs_loss_scale)) {
    throw py::value_error("loss scales must be finite and > 0");
  }
  MatchOptions options;
  options.solver = SolverKindFromString(solver);
  options.matching.w_rcs = w_rcs;
  options.matching.geometric_loss = {LossTypeFromString(loss), loss_scale};
  options.matching.rcs_loss = {LossTypeFromString(rcs_loss), rcs_loss_scale};
  return options;
}

// match's docstring, its name lists from the library's name tables.
const char* MatchDoc() {
  static const std::string doc =
      "Matches a Scan against a GaussianMap from `initial` (T_world_radar, 4x4 or [x y z qx qy qz qw]), "
      "minimising eq. 2 coarse to fine as `radargauss localize` does. solver: " +
      Joined(ScanMatcherNames()) + "; loss and rcs_loss: " + Joined(LossNames()) + ".";
  return doc.c_str();
}

void BindMatchResult(py::module_& m) {
  py::class_<ScanMatchingResult>(m, "MatchResult", "The outcome of one scan match.")
      .def_property_readonly("pose", [](const ScanMatchingResult& r) { return PoseToMatrix(r.pose); },
                             "T_world_radar at the end, 4x4")
      .def_property_readonly("pose_tum", [](const ScanMatchingResult& r) { return PoseToTum(r.pose); },
                             "the same as [x y z qx qy qz qw], exactly the numbers a TUM file gets")
      .def_readonly("iterations", &ScanMatchingResult::iterations)
      .def_readonly("cost", &ScanMatchingResult::final_cost)
      .def_readonly("converged", &ScanMatchingResult::converged)
      .def_readonly("reason", &ScanMatchingResult::reason)
      .def_readonly("geometric_residuals", &ScanMatchingResult::n_geo)
      .def_readonly("rcs_residuals", &ScanMatchingResult::n_rcs)
      .def_readonly("time_ms", &ScanMatchingResult::time_ms)
      .def_property_readonly("information", [](const ScanMatchingResult& r) { return MatrixToArray<6, 6>(r.information); },
                             "6x6 Gauss-Newton matrix of eq. 2 over [dt (world); dphi (radar)]");
}

py::dict StepToDict(const OdometryStep& s) {
  py::dict d;
  d["stamp"] = s.stamp;
  d["pose"] = PoseToMatrix(s.pose);
  d["points"] = s.points;
  d["static_points"] = s.static_points;
  d["velocity_measured"] = s.velocity_measured;
  d["velocity"] = MatrixToArray<3, 1>(s.velocity);
  d["standstill"] = s.standstill;
  d["matched"] = s.matched;
  d["iterations"] = s.iterations;
  d["cost"] = s.final_cost;
  d["converged"] = s.converged;
  d["reason"] = s.reason;
  d["keyframe"] = s.keyframe;
  d["active_gaussians"] = s.active_gaussians;
  d["time_ms"] = s.time_ms;
  d["information"] = MatrixToArray<6, 6>(s.information);
  return d;
}

void BindOdometry(py::module_& m) {
  py::class_<RadarOdometry>(m, "RadarOdometry",
                            "Radar odometry on a map it builds as it goes (docs/design.md, \"Odometry\"): "
                            "register scans in time order.")
      .def(py::init([](double w_rcs, const std::string& solver, double velocity_weight, double rotation_weight,
                       double keyframe_distance, double active_radius, const py::object& initial_pose) {
             OdometryOptions options;
             if (!initial_pose.is_none()) options.initial_pose = PoseFromPython(initial_pose, "initial_pose");
             options.match = MatchOptionsFrom(w_rcs, solver, "trivial", 1.0, "cauchy", 1.0);
             options.velocity_weight = velocity_weight;
             options.rotation_weight = rotation_weight;
             options.keyframe_distance = keyframe_distance;
             options.map.active_radius = active_radius;
             ValidateOptions(options);
             return std::make_unique<RadarOdometry>(options);
           }),
           py::arg("w_rcs") = 0.0, py::arg("solver") = "gn", py::arg("velocity_weight") = OdometryOptions().velocity_weight,
           py::arg("rotation_weight") = OdometryOptions().rotation_weight,
           py::arg("keyframe_distance") = OdometryOptions().keyframe_distance,
           py::arg("active_radius") = LocalMapOptions().active_radius, py::arg("initial_pose") = py::none(),
           "w_rcs and solver as in match; velocity_weight of the Doppler term and rotation_weight of the "
           "rotation term (0: off); keyframe_distance (m); "
           "active_radius (m) of the map kept for matching; initial_pose: T_world_radar of the first scan.")
      .def(
          "register",
          [](RadarOdometry& odometry, const RadarScan& scan) {
            const OdometryStep* step = nullptr;
            {
              py::gil_scoped_release release;
              step = &odometry.Register(scan);
            }
            return StepToDict(*step);
          },
          py::arg("scan"), "Adds the next scan; returns what happened to it (pose 4x4, reason, ...).")
      .def("trajectory", [](const RadarOdometry& o) { return TrajectoryToArrays(o.trajectory()); },
           "(stamps, poses (N, 7)) so far")
      .def("map", [](const RadarOdometry& o) { return std::make_shared<PyMap>(o.map().GlobalMap()); },
           "The map built so far, the Gaussians that left the active radius included")
      .def("__len__", [](const RadarOdometry& o) { return o.steps().size(); });
}

py::dict DriftToDict(const SegmentDrift& d) {
  py::dict out;
  out["length_m"] = d.length;
  out["segments"] = d.segments;
  out["translation_percent"] = d.translation;
  out["horizontal_percent"] = d.horizontal;
  out["rotation_deg_per_m"] = d.rotation;
  return out;
}

py::dict StatisticsToDict(const ErrorStatistics& s) {
  py::dict out;
  out["rmse"] = s.rmse;
  out["mean"] = s.mean;
  out["median"] = s.median;
  out["max"] = s.max;
  return out;
}

}  // namespace

void BindMatch(py::module_& m) {
  BindMatchResult(m);
  m.def(
      "match",
      [](const RadarScan& scan, const PyMap& map, const py::handle& initial, double w_rcs, const std::string& solver,
         const std::string& loss, double loss_scale, const std::string& rcs_loss, double rcs_loss_scale) {
        const SE3d start = PoseFromPython(initial, "initial");
        const MatchOptions options = MatchOptionsFrom(w_rcs, solver, loss, loss_scale, rcs_loss, rcs_loss_scale);
        const MatchingMap& matching = map.matching();
        py::gil_scoped_release release;
        return Match(scan, matching, start, options);
      },
      py::arg("scan"), py::arg("map"), py::arg("initial"), py::arg("w_rcs") = 0.0, py::arg("solver") = "gn",
      py::arg("loss") = "trivial", py::arg("loss_scale") = 1.0, py::arg("rcs_loss") = "cauchy",
      py::arg("rcs_loss_scale") = 1.0,
      MatchDoc())
  ;
  m.def(
      "initial_errors",
      [](std::size_t scans, double max_translation, double max_rotation_deg, std::uint32_t seed) {
        const std::vector<SE3d> errors = InitialErrors(scans, max_translation, max_rotation_deg, seed);
        Array out = NewArray({py::ssize_t(errors.size()), 7});
        for (std::size_t i = 0; i < errors.size(); ++i) {
          const Array tum = PoseToTum(errors[i]);
          std::copy(tum.data(), tum.data() + 7, out.mutable_data() + 7 * i);
        }
        return out;
      },
      py::arg("scans"), py::arg("max_translation") = 2.0, py::arg("max_rotation_deg") = 5.0, py::arg("seed") = 42,
      "The seeded errors E of `radargauss localize` (its --max-translation, --max-rotation, --seed): the "
      "initial pose of scan i is compose(reference_i, E_i). (N, 7).");
  m.def(
      "compose",
      [](const py::handle& a, const py::handle& b) { return PoseToTum(PoseFromPython(a, "a") * PoseFromPython(b, "b")); },
      py::arg("a"), py::arg("b"), "The rigid transform a * b as [x y z qx qy qz qw].");
  BindOdometry(m);
  m.def(
      "evaluate",
      [](const py::tuple& estimate, const py::tuple& reference, const std::string& align) {
        if (estimate.size() != 2 || reference.size() != 2) {
          throw py::value_error("estimate and reference are (stamps, poses) pairs, as read_tum gives");
        }
        EvaluationOptions options;
        options.alignment = AlignmentFromString(align);
        const Evaluation e = EvaluateTrajectory(TrajectoryFromArrays(estimate[0], estimate[1], "estimate"),
                                                TrajectoryFromArrays(reference[0], reference[1], "reference"), options);
        py::dict out;
        out["matched"] = e.matched;
        out["path_length_m"] = e.path_length;
        out["ate_translation_m"] = StatisticsToDict(e.ate_translation);
        out["ate_rotation_deg"] = StatisticsToDict(e.ate_rotation);
        out["rpe"] = DriftToDict(e.rpe_mean);
        py::list segments;
        for (const SegmentDrift& d : e.rpe) segments.append(DriftToDict(d));
        out["rpe_segments"] = segments;
        return out;
      },
      py::arg("estimate"), py::arg("reference"), py::arg("align") = "se3",
      "ATE and RPE of `radargauss evaluate`: align se3, sim3, first or none.");
}

}  // namespace radargauss::python
