// SPDX-License-Identifier: BSD-3-Clause
// Radar SLAM and relocalisation in Python (docs/design.md, "SLAM", "Relocalisation").
#include <pybind11/stl.h>

#include <string>

#include "bindings.hpp"
#include "option_fields.hpp"
#include "radargauss/slam/radar_slam.hpp"
#include "radargauss/slam/relocalization.hpp"

namespace radargauss::python {

namespace {

// Place recognition's keywords, shared by RadarSlam and Relocalizer.
PlaceRecognitionOptions PlaceRecognitionFrom(const std::string& descriptor, int candidates) {
  PlaceRecognitionOptions options;
  options.descriptor = PlaceDescriptorKindFromString(descriptor);  // std::invalid_argument: ValueError
  options.candidates = candidates;
  return options;
}

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

std::unique_ptr<LockedSlam> MakeSlam(const std::string& descriptor, double submap_distance, double min_loop_path,
                                     int candidates, const std::string& loop_rejection,
                                     const std::string& graph_initialization, const py::kwargs& kwargs) {
  SlamOptions options;
  options.odometry = OptionsFrom(OdometryFields(), kwargs);
  options.place_recognition = PlaceRecognitionFrom(descriptor, candidates);
  options.submap_distance = submap_distance;
  options.min_loop_path = min_loop_path;
  options.graph.loop_rejection = LoopRejectionFromString(loop_rejection);
  options.graph.initialization = GraphInitializationFromString(graph_initialization);
  return std::make_unique<LockedSlam>(std::make_unique<RadarSlam>(options));  // validates
}

std::unique_ptr<LockedRelocalizer> MakeRelocalizer(const PyMap& map, const std::string& descriptor,
                                                   double submap_distance, int candidates, const py::kwargs& kwargs) {
  RelocalizationOptions options;
  options.odometry = OptionsFrom(OdometryFields(), kwargs);
  options.place_recognition = PlaceRecognitionFrom(descriptor, candidates);
  options.submap_distance = submap_distance;
  return std::make_unique<LockedRelocalizer>(std::make_unique<Relocalizer>(map.map(), options));
}

}  // namespace

void BindSlam(py::module_& m) {
  py::class_<LockedSlam>(m, "RadarSlam",
                         "Radar SLAM (docs/design.md, \"SLAM\"): odometry, keyframes with submaps, place recognition, "
                         "verified loops on a pose graph. Keywords: descriptor ('scan-context' or 'radon'), "
                         "submap_distance, min_loop_path, candidates, loop_rejection ('loss', 'switchable', "
                         "'graduated'), graph_initialization ('current', 'chordal'), and any keyword of "
                         "RadarOdometry. Threads may share one: its calls take turns.")
      .def(py::init(&MakeSlam), py::arg("descriptor") = "scan-context", py::arg("submap_distance") = 10.0,
           py::arg("min_loop_path") = 150.0, py::arg("candidates") = PlaceRecognitionOptions().candidates,
           py::arg("loop_rejection") = "graduated", py::arg("graph_initialization") = "current")
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
          [](LockedSlam& slam, const std::vector<RadarScan>& scans) {
            return std::make_shared<PyMap>(slam.With([&](RadarSlam& s) { return BuildPlaceMap(scans, s); }));
          },
          py::arg("scans"), "The map of the place from the registered scans (in order), with the keyframes as places");
  py::class_<LockedRelocalizer>(m, "Relocalizer",
                                "Relocalisation in a map of RadarSlam without an initial pose (docs/design.md, "
                                "\"Relocalisation\"). Keywords: descriptor, submap_distance, candidates, and any "
                                "keyword of RadarOdometry. Threads may share one: its calls take turns.")
      .def(py::init(&MakeRelocalizer), py::arg("map"), py::arg("descriptor") = "scan-context",
           py::arg("submap_distance") = 10.0, py::arg("candidates") = PlaceRecognitionOptions().candidates)
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
