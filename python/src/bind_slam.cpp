// SPDX-License-Identifier: BSD-3-Clause
// Radar SLAM and relocalisation in Python (docs/design/slam.md, "SLAM", "Relocalisation").
#include <pybind11/stl.h>

#include <optional>
#include <string>

#include "bindings.hpp"
#include "option_fields.hpp"
#include "radargauss/slam/radar_slam.hpp"
#include "radargauss/slam/relocalization.hpp"

namespace radargauss::python {

namespace {

py::dict LoopToDict(const LoopCandidate& c) {
  py::dict d;
  d["query"] = c.query;
  d["candidate"] = c.candidate;
  d["distance"] = c.distance;
  d["yaw"] = c.yaw;
  d["verified"] = c.verified;
  d["injected"] = c.injected;
  d["accepted"] = c.check.accepted;
  d["relative"] = PoseToMatrix(c.check.relative);
  d["reason"] = c.check.reason;
  return d;
}

using LockedSlam = Locked<RadarSlam>;
using LockedRelocalizer = Locked<Relocalizer>;

std::unique_ptr<LockedSlam> MakeSlam(const py::kwargs& kwargs) {
  const SlamOptions options = OptionsFrom(SlamOptionTable(), kwargs);
  return std::make_unique<LockedSlam>(std::make_unique<RadarSlam>(options));  // validates
}

std::unique_ptr<LockedRelocalizer> MakeRelocalizer(const PyMap& map, const py::kwargs& kwargs) {
  const RelocalizationOptions options = OptionsFrom(RelocalizationOptionTable(), kwargs);
  return std::make_unique<LockedRelocalizer>(std::make_unique<Relocalizer>(map.map(), options));
}

const char* SlamDoc() {
  static const std::string doc =
      "Radar SLAM (docs/design/slam.md, \"SLAM\"): odometry, keyframes with submaps, place recognition, verified loops "
      "on a pose graph. Threads may share one: its calls take turns.\n\nParameters\n----------\n"
      "**options\n    any of the keywords below (option_fields('slam') lists them)\n" +
      ParametersDoc(SlamOptionTable());
  return doc.c_str();
}

const char* RelocalizerDoc() {
  static const std::string doc =
      "Relocalisation in a map of RadarSlam without an initial pose (docs/design/slam.md, \"Relocalisation\"). Threads "
      "may share one: its calls take turns.\n\nParameters\n----------\nmap : Map\n    a map of RadarSlam, with "
      "places\n**options\n    any of the keywords below (option_fields('relocalization') lists them)\n" +
      ParametersDoc(RelocalizationOptionTable());
  return doc.c_str();
}

}  // namespace

void BindSlam(py::module_& m) {
  py::class_<LockedSlam>(m, "RadarSlam", SlamDoc())
      .def(py::init(&MakeSlam))
      .def(
          "register",
          [](LockedSlam& slam, const RadarScan& scan) { slam.With([&](RadarSlam& s) { s.Register(scan); }); },
          py::arg("scan"), "Adds the next scan (stamps must increase).")
      .def(
          "finish", [](LockedSlam& slam) { slam.With([](RadarSlam& s) { s.Finish(); }); },
          "Closes the last keyframe (described and searched): call after the last scan.")
      .def(
          "trajectory",
          [](LockedSlam& slam) { return TrajectoryToArrays(slam.With([](RadarSlam& s) { return s.trajectory(); })); },
          "(stamps (N,), poses (N, 7)): every scan at its keyframe's optimised pose")
      .def(
          "odometry_trajectory",
          [](LockedSlam& slam) {
            return TrajectoryToArrays(slam.With([](RadarSlam& s) { return s.odometry().trajectory(); }));
          },
          "(stamps (N,), poses (N, 7)) of the odometry alone")
      .def(
          "loops",
          [](LockedSlam& slam) {
            py::list loops;
            for (const LoopCandidate& c : slam.With([](RadarSlam& s) { return s.candidates(); })) {
              loops.append(LoopToDict(c));
            }
            return loops;
          },
          "Every compared candidate as a dict: query, candidate, distance, yaw, verified, accepted, relative, reason")
      .def_property_readonly(
          "keyframes", [](LockedSlam& slam) { return slam.With([](RadarSlam& s) { return s.keyframes().size(); }); })
      .def(
          "place_map",
          [](LockedSlam& slam, std::optional<std::vector<RadarScan>> scans) {
            return std::make_shared<PyMap>(
                slam.With([&](RadarSlam& s) { return scans ? BuildPlaceMap(*scans, s) : BuildPlaceMap(s); }));
          },
          py::arg("scans") = py::none(),
          "The map of the place, with the keyframes as places: from the registered scans (in order), or without "
          "them from the static points the SLAM holds (hold_map_points; a revisit within place_merge_distance "
          "holds none)")
      .def_property_readonly(
          "place_map_bytes",
          [](LockedSlam& slam) { return slam.With([](RadarSlam& s) { return s.place_map_bytes(); }); },
          "Bytes of the static points held for the map of the place");
  py::class_<LockedRelocalizer>(m, "Relocalizer", RelocalizerDoc())
      .def(py::init(&MakeRelocalizer), py::arg("map"))
      .def(
          "register",
          [](LockedRelocalizer& relocalizer, const RadarScan& scan) {
            const RelocalizationStep step = relocalizer.With([&](Relocalizer& r) { return r.Register(scan); });
            py::dict d;
            d["stamp"] = step.stamp;
            d["fixed"] = step.fixed;
            d["pose"] = step.fixed ? py::object(PoseToMatrix(step.pose)) : py::object(py::none());
            d["matched"] = step.matched;
            d["reason"] = step.reason;
            return d;
          },
          py::arg("scan"), "Adds the next scan; a dict with fixed, pose (4x4, or None before a fix), matched, reason")
      .def_property_readonly(
          "first_fix", [](LockedRelocalizer& r) { return r.With([](Relocalizer& x) { return x.first_fix(); }); },
          "Index of the scan of the first fix, or None");
}

}  // namespace radargauss::python
