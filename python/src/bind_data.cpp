// SPDX-License-Identifier: BSD-3-Clause
// Scans, sequences, trajectories and the simulator in Python.
#include <pybind11/stl.h>

#include <algorithm>

#include "bindings.hpp"
#include "radargauss/io/pcd.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/experiment/run_mcap.hpp"
#include "radargauss/io/sequence.hpp"
#include "radargauss/simulator/simulator.hpp"
#include "radargauss/core/trajectory.hpp"

namespace radargauss::python {

namespace {

// One column of a scan's points as an (N,) array.
template <typename Get>
Array Column(const RadarScan& scan, const Get& get) {
  Array out = NewArray({py::ssize_t(scan.points.size())});
  double* p = out.mutable_data();
  for (const RadarPoint& point : scan.points) *p++ = get(point);
  return out;
}

Array Positions(const RadarScan& scan) {
  Array out = NewArray({py::ssize_t(scan.points.size()), 3});
  double* p = out.mutable_data();
  for (const RadarPoint& point : scan.points) {
    for (int k = 0; k < 3; ++k) *p++ = point.position[k];
  }
  return out;
}

Array Poses(const std::vector<SE3d>& poses) {
  Array out = NewArray({py::ssize_t(poses.size()), 7});
  auto view = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Array tum = PoseToTum(poses[i]);
    for (int k = 0; k < 7; ++k) view(py::ssize_t(i), k) = tum.at(k);
  }
  return out;
}

// (N, 4, 4): the matrices numpy users compose with @.
Array PoseMatrices(const std::vector<SE3d>& poses) {
  Array out = NewArray({py::ssize_t(poses.size()), 4, 4});
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Array matrix = PoseToMatrix(poses[i]);
    std::copy(matrix.data(), matrix.data() + 16, out.mutable_data() + 16 * i);
  }
  return out;
}

void BindScan(py::module_& m) {
  py::class_<RadarScan>(m, "Scan",
                        "One radar scan: points (N, 3) in the radar frame, Doppler (m/s, positive "
                        "receding) and RCS (dBsm), each a copy as a numpy array.")
      .def(py::init([](const py::handle& points, const py::object& doppler, const py::object& rcs, double stamp) {
             return ScanFromArrays(points, doppler, rcs, stamp);
           }),
           py::arg("points"), py::arg("doppler") = py::none(), py::arg("rcs") = py::none(), py::arg("stamp") = 0.0)
      .def_readonly("stamp", &RadarScan::timestamp)
      .def_readonly("has_doppler", &RadarScan::has_doppler)
      .def_readonly("has_rcs", &RadarScan::has_rcs)
      .def_property_readonly("points", &Positions)
      .def_property_readonly(
          "doppler", [](const RadarScan& s) { return Column(s, [](const RadarPoint& p) { return p.doppler; }); })
      .def_property_readonly("rcs",
                             [](const RadarScan& s) { return Column(s, [](const RadarPoint& p) { return p.rcs; }); })
      .def("__len__", [](const RadarScan& s) { return s.points.size(); })
      .def("__repr__", [](const RadarScan& s) {
        return "<radargauss.Scan " + std::to_string(s.points.size()) + " points at " + std::to_string(s.timestamp) +
               ">";
      });
}

void BindSequence(py::module_& m) {
  py::class_<Sequence>(m, "Sequence", "Scans in time order and, with ground truth, the pose of each.")
      .def_readonly("scans", &Sequence::scans)
      .def_readonly("layout", &Sequence::layout)
      .def_readonly("sources", &Sequence::scan_sources)
      .def_property_readonly(
          "poses", [](const Sequence& s) { return Poses(s.poses); },
          "T_world_radar of each scan as (N, 7) [x y z qx qy qz qw]; empty without ground truth")
      .def_property_readonly(
          "poses_matrix", [](const Sequence& s) { return PoseMatrices(s.poses); },
          "The same as (N, 4, 4) matrices, to compose with @")
      .def_property_readonly("stamps",
                             [](const Sequence& s) {
                               Array out = NewArray({py::ssize_t(s.scans.size())});
                               for (std::size_t i = 0; i < s.scans.size(); ++i)
                                 out.mutable_at(py::ssize_t(i)) = s.scans[i].timestamp;
                               return out;
                             })
      .def("__len__", [](const Sequence& s) { return s.scans.size(); });
  m.def(
      "pose_matrix", [](const py::handle& pose) { return PoseToMatrix(PoseFromPython(pose, "pose")); }, py::arg("pose"),
      "A pose [x y z qx qy qz qw] (or 4x4) as its 4x4 matrix.");
  m.def(
      "pose_matrices",
      [](const py::handle& poses) {
        std::vector<SE3d> out;
        for (const py::handle row : py::iter(poses))
          out.push_back(PoseFromPython(row, "poses[" + std::to_string(out.size()) + "]"));
        return PoseMatrices(out);
      },
      py::arg("poses"), "Poses (N, 7) [x y z qx qy qz qw] (or (N, 4, 4)) as (N, 4, 4) matrices.");
  m.def(
      "read_sequence",
      [](const std::string& path, const std::string& gt, const std::string& extrinsic, const std::string& bag,
         const std::string& topic, const std::string& rcs_field, const std::string& doppler_field,
         double elevation_bias_deg) {
        SequenceOptions options;
        options.sequence_dir = path;
        options.ground_truth = gt;
        options.extrinsic = extrinsic;
        options.bag = bag;
        options.topic = topic;
        options.fields.rcs_field = rcs_field;
        options.fields.doppler_field = doppler_field;
        options.elevation_bias_deg = elevation_bias_deg;
        py::gil_scoped_release release;
        return LoadSequence(options);
      },
      py::arg("path") = "", py::arg("gt") = "", py::arg("extrinsic") = "auto", py::arg("bag") = "",
      py::arg("topic") = "", py::arg("rcs_field") = "", py::arg("doppler_field") = "",
      py::arg("elevation_bias_deg") = 0.0,
      "Reads a sequence as `radargauss info` does: a Snail-Radar folder, a folder of .pcd or .bin scans "
      "(path), or a bag (bag, topic: a ROS1 .bag, a ROS 2 .db3 or .mcap, a rosbag2 folder); gt: a TUM file of "
      "reference poses, extrinsic T_gt_radar; "
      "elevation_bias_deg removed from every point.");
  m.def(
      "read_pcd", [](const std::string& path) { return ReadPcdScan(path); }, py::arg("path"),
      "One PCD scan (ascii, binary or binary_compressed); the stamp from a <secs>.<nsecs>.pcd name.");
}

void BindTrajectories(py::module_& m) {
  m.def(
      "read_tum",
      [](const std::string& path) {
        const Trajectory trajectory = ReadTum(path);
        return TrajectoryToArrays(trajectory);
      },
      py::arg("path"), "A TUM file as (stamps (N,), poses (N, 7) [x y z qx qy qz qw]).");
  m.def(
      "read_bag_topics",
      [](const std::string& path) {
        py::list topics;
        for (const BagTopic& t : ListBagTopics(path)) {
          py::dict d;
          d["name"] = t.name;
          d["type"] = t.type;
          d["messages"] = t.messages;
          d["first"] = t.first;
          d["last"] = t.last;
          topics.append(d);
        }
        return topics;
      },
      py::arg("path"),
      "The topics of a bag of any kind (ROS1 .bag, ROS 2 .db3 or .mcap, rosbag2 folder): dicts of name, type, "
      "messages and the first and last record time (s).");
  m.def(
      "read_bag_poses",
      [](const std::string& path, const std::string& topic, const std::string& child_frame) {
        Trajectory trajectory;
        {
          py::gil_scoped_release release;
          trajectory = ReadBagPoses(path, topic, child_frame);
        }
        return TrajectoryToArrays(trajectory);
      },
      py::arg("path"), py::arg("topic"), py::arg("child_frame") = "",
      "Poses of a ROS 2 bag's topic (PoseStamped, Odometry, TFMessage with child_frame, or the last Path) as "
      "(stamps (N,), poses (N, 7)).");
  m.def(
      "write_run_mcap",
      [](const std::string& path, const py::handle& stamps, const py::handle& poses, const py::object& map,
         const py::object& reference_stamps, const py::object& reference, const py::object& scans,
         double ellipsoid_sigma) {
        RunForViewer run;
        for (const StampedPose& p : TrajectoryFromArrays(stamps, poses, "poses")) {
          run.stamps.push_back(p.time);
          run.poses.push_back(p.pose);
        }
        if (!map.is_none()) {
          if (!py::isinstance<PyMap>(map)) {
            throw py::type_error("map must be a GaussianMap or None, not " +
                                 std::string(py::str(map.get_type().attr("__name__"))));
          }
          run.map = map.cast<const PyMap&>().map();
        }
        if (!reference.is_none()) {
          for (const StampedPose& p : TrajectoryFromArrays(reference_stamps, reference, "reference")) {
            run.reference_stamps.push_back(p.time);
            run.reference.push_back(p.pose);
          }
        }
        if (!scans.is_none()) run.scans = scans.cast<std::vector<RadarScan>>();
        RunMcapOptions options;
        options.ellipsoid_sigma = ellipsoid_sigma;
        py::gil_scoped_release release;
        WriteRunMcap(path, run, options);
      },
      py::arg("path"), py::arg("stamps"), py::arg("poses"), py::arg("map") = py::none(),
      py::arg("reference_stamps") = py::none(), py::arg("reference") = py::none(), py::arg("scans") = py::none(),
      py::arg("ellipsoid_sigma") = 2.0,
      "Writes a trajectory (stamps (N,), poses (N, 7) or (N, 4, 4): T_map_radar), and optionally a GaussianMap, a "
      "reference and the scans (one per pose, registered by it) as an MCAP file a robotics viewer opens, as "
      "`radargauss export` does.");
  m.def(
      "write_tum",
      [](const std::string& path, const py::handle& stamps, const py::handle& poses) {
        WriteTum(path, TrajectoryFromArrays(stamps, poses, "poses"));
      },
      py::arg("path"), py::arg("stamps"), py::arg("poses"),
      "Writes stamps (N,) and poses (N, 7) or (N, 4, 4) as a TUM file (9 decimals), atomically.");
}

void BindSimulator(py::module_& m) {
  m.def(
      "simulate",
      [](std::uint32_t seed, int scans, const std::string& config) {
        SimulationConfig c = config.empty() ? SimulationConfig() : LoadSimulationConfig(config);
        c.seed = seed;
        if (scans > 0) c.scans = scans;
        ValidateSimulationConfig(c, "simulate");
        py::gil_scoped_release release;
        return AsSequence(Simulate(c));
      },
      py::arg("seed") = 1, py::arg("scans") = 0, py::arg("config") = "",
      "The synthetic 4D radar drive of `radargauss simulate` (configs/synthetic_world.yaml) as a Sequence with "
      "its ground-truth poses; scans > 0 overrides the config's count.");
}

}  // namespace

py::tuple TrajectoryToArrays(const Trajectory& trajectory) {
  Array stamps = NewArray({py::ssize_t(trajectory.size())});
  std::vector<SE3d> poses;
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    stamps.mutable_at(py::ssize_t(i)) = trajectory[i].time;
    poses.push_back(trajectory[i].pose);
  }
  return py::make_tuple(stamps, Poses(poses));
}

Trajectory TrajectoryFromArrays(const py::handle& stamps, const py::handle& poses, const std::string& name) {
  const Array times = CheckedArray(stamps, {-1}, name + " stamps");
  const py::ssize_t n = times.shape(0);
  const py::array array = py::array::ensure(poses);
  if (!array || array.ndim() < 2 || array.shape(0) != n) {
    throw py::value_error(name + " must be (N, 7) or (N, 4, 4) with N = " + std::to_string(n) + " stamps");
  }
  Trajectory trajectory;
  for (py::ssize_t i = 0; i < n; ++i) {
    const SE3d pose = PoseFromPython(array[py::int_(i)], name + "[" + std::to_string(i) + "]");
    try {
      trajectory.Append(times.at(i), pose);
    } catch (const std::invalid_argument&) {
      throw py::value_error(name + " stamps must increase strictly");
    }
  }
  return trajectory;
}

void BindData(py::module_& m) {
  BindScan(m);
  BindSequence(m);
  BindTrajectories(m);
  BindSimulator(m);
}

}  // namespace radargauss::python
