// SPDX-License-Identifier: BSD-3-Clause
// Radar rigs in Python (docs/design/rig.md): the rig file and the rig's
// twist from its radars' Doppler.
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "option_fields.hpp"
#include "radargauss/core/rig_twist.hpp"
#include "radargauss/io/rig.hpp"

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

}  // namespace

void BindRig(py::module_& m) {
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
