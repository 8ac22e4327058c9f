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

std::unique_ptr<RadarSlam> MakeSlam(const std::string& descriptor, double submap_distance, double min_loop_path,
                                    int candidates, const std::string& loop_rejection,
                                    const std::string& graph_initialization, const py::kwargs& kwargs) {
  SlamOptions options;
  options.odometry = OptionsFrom(OdometryFields(), kwargs);
  options.place_recognition = PlaceRecognitionFrom(descriptor, candidates);
  options.submap_distance = submap_distance;
  options.min_loop_path = min_loop_path;
  options.graph.loop_rejection = LoopRejectionFromString(loop_rejection);
  options.graph.initialization = GraphInitializationFromString(graph_initialization);
  return std::make_unique<RadarSlam>(options);  // validates
}

std::unique_ptr<Relocalizer> MakeRelocalizer(const PyMap& map, const std::string& descriptor, double submap_distance,
                                             int candidates, const py::kwargs& kwargs) {
  RelocalizationOptions options;
  options.odometry = OptionsFrom(OdometryFields(), kwargs);
  options.place_recognition = PlaceRecognitionFrom(descriptor, candidates);
  options.submap_distance = submap_distance;
  return std::make_unique<Relocalizer>(map.map(), options);
}

}  // namespace

void BindSlam(py::module_& m) {
  py::class_<RadarSlam>(m, "RadarSlam",
                        "Radar SLAM (docs/design.md, \"SLAM\"): odometry, keyframes with submaps, place recognition, "
                        "verified loops on a pose graph. Keywords: descriptor ('scan-context' or 'radon'), "
                        "submap_distance, min_loop_path, candidates, loop_rejection ('loss', 'switchable', "
                        "'graduated'), graph_initialization ('current', 'chordal'), and any keyword of "
                        "RadarOdometry.")
      .def(py::init(&MakeSlam), py::arg("descriptor") = "scan-context", py::arg("submap_distance") = 10.0,
           py::arg("min_loop_path") = 150.0, py::arg("candidates") = PlaceRecognitionOptions().candidates,
           py::arg("loop_rejection") = "graduated", py::arg("graph_initialization") = "current")
      .def(
          "register",
          [](RadarSlam& slam, const RadarScan& scan) {
            py::gil_scoped_release release;
            slam.Register(scan);
          },
          py::arg("scan"), "Adds the next scan (stamps must increase).")
      .def("finish", &RadarSlam::Finish, "Closes the last keyframe (described and searched): call after the last scan.")
      .def("trajectory", [](const RadarSlam& s) { return TrajectoryToArrays(s.trajectory()); },
           "(stamps (N,), poses (N, 7)): every scan at its keyframe's optimised pose")
      .def("odometry_trajectory", [](const RadarSlam& s) { return TrajectoryToArrays(s.odometry().trajectory()); },
           "(stamps (N,), poses (N, 7)) of the odometry alone")
      .def(
          "loops",
          [](const RadarSlam& s) {
            py::list loops;
            for (const LoopCandidate& c : s.candidates()) loops.append(LoopToDict(c));
            return loops;
          },
          "Every compared candidate as a dict: query, candidate, distance, yaw, verified, accepted, relative, reason")
      .def_property_readonly("keyframes", [](const RadarSlam& s) { return s.keyframes().size(); })
      .def(
          "place_map",
          [](const RadarSlam& s, const std::vector<RadarScan>& scans) {
            return std::make_shared<PyMap>(BuildPlaceMap(scans, s));
          },
          py::arg("scans"), "The map of the place from the registered scans (in order), with the keyframes as places");
  py::class_<Relocalizer>(m, "Relocalizer",
                          "Relocalisation in a map of RadarSlam without an initial pose (docs/design.md, "
                          "\"Relocalisation\"). Keywords: descriptor, submap_distance, candidates, and any keyword of "
                          "RadarOdometry.")
      .def(py::init(&MakeRelocalizer), py::arg("map"), py::arg("descriptor") = "scan-context",
           py::arg("submap_distance") = 10.0, py::arg("candidates") = PlaceRecognitionOptions().candidates)
      .def(
          "register",
          [](Relocalizer& relocalizer, const RadarScan& scan) {
            const RelocalizationStep* step = nullptr;
            {
              py::gil_scoped_release release;
              step = &relocalizer.Register(scan);
            }
            py::dict d;
            d["stamp"] = step->stamp;
            d["fixed"] = step->fixed;
            d["pose"] = step->fixed ? py::object(PoseToMatrix(step->pose)) : py::object(py::none());
            d["matched"] = step->matched;
            d["reason"] = step->reason;
            return d;
          },
          py::arg("scan"), "Adds the next scan; a dict with fixed, pose (4x4, or None before a fix), matched, reason")
      .def_property_readonly("first_fix", [](const Relocalizer& r) { return r.first_fix(); },
                             "Index of the scan of the first fix, or None");
}

}  // namespace radargauss::python
