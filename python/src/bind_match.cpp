// SPDX-License-Identifier: BSD-3-Clause
// Scan matching and trajectory evaluation in Python.
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "bindings.hpp"
#include "option_fields.hpp"
#include "radargauss/experiment/evaluation.hpp"
#include "radargauss/experiment/experiment.hpp"
#include "radargauss/radargauss.hpp"

namespace radargauss::python {

namespace {

// match's docstring (numpydoc), its keywords from the option table.
const char* MatchDoc() {
  static const std::string doc =
      "Matches a Scan against a GaussianMap, minimising eq. 2 coarse to fine as `radargauss localize` does.\n\n"
      "Parameters\n----------\n"
      "scan : Scan\n    the scan, in the radar frame\n"
      "map : GaussianMap\n    the map (its coarse-to-fine levels are built on first use)\n"
      "initial : array (4, 4) or (7,)\n    T_world_radar to start from\n"
      "**options\n    any of the keywords below (match_options() gives them all with their values)\n" +
      ParametersDoc(MatchOptionTable()) + "\nReturns\n-------\nMatchResult\n";
  return doc.c_str();
}

void BindMatchResult(py::module_& m) {
  py::class_<ScanMatchingResult>(m, "MatchResult", "The outcome of one scan match.")
      .def_property_readonly(
          "pose", [](const ScanMatchingResult& r) { return PoseToMatrix(r.pose); }, "T_world_radar at the end, 4x4")
      .def_property_readonly(
          "pose_tum", [](const ScanMatchingResult& r) { return PoseToTum(r.pose); },
          "the same as [x y z qx qy qz qw], exactly the numbers a TUM file gets")
      .def_readonly("iterations", &ScanMatchingResult::iterations)
      .def_readonly("cost", &ScanMatchingResult::final_cost)
      .def_readonly("converged", &ScanMatchingResult::converged)
      .def_readonly("reason", &ScanMatchingResult::reason)
      .def_readonly("geometric_residuals", &ScanMatchingResult::n_geo)
      .def_readonly("rcs_residuals", &ScanMatchingResult::n_rcs)
      .def_readonly("time_ms", &ScanMatchingResult::time_ms)
      .def_property_readonly(
          "information", [](const ScanMatchingResult& r) { return MatrixToArray<6, 6>(r.information); },
          "6x6 Gauss-Newton matrix of eq. 2 over [dt (world); dphi (radar)]");
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
      [](const RadarScan& scan, const PyMap& map, const py::handle& initial, const py::kwargs& kwargs) {
        const SE3d start = PoseFromPython(initial, "initial");
        const MatchOptions options = OptionsFrom(MatchOptionTable(), kwargs);
        const MatchingMap& matching = map.matching();
        py::gil_scoped_release release;
        return Match(scan, matching, start, options);
      },
      py::arg("scan"), py::arg("map"), py::arg("initial"), MatchDoc());
  m.def(
      "match_options",
      [](const py::kwargs& kwargs) {
        const MatchOptions options = OptionsFrom(MatchOptionTable(), kwargs);
        MakeScanMatcher(options);  // validates: std::invalid_argument is a ValueError
        return OptionsToDict(MatchOptionTable(), options);
      },
      "Every option of match, the given keywords set (checked as match checks them), as a dict.");
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
      [](const py::handle& a, const py::handle& b) {
        return PoseToTum(PoseFromPython(a, "a") * PoseFromPython(b, "b"));
      },
      py::arg("a"), py::arg("b"), "The rigid transform a * b as [x y z qx qy qz qw].");
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
        out["alignment_note"] = e.alignment_note;
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
