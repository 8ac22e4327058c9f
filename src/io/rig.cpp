// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/rig.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <set>
#include <utility>

#include <Eigen/Geometry>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/yaml_file.hpp"

namespace radargauss {

namespace {

namespace fs = std::filesystem;

constexpr double kRotationTolerance = 1e-6;

// A path of the rig file, relative to the file's folder unless absolute.
std::string BesideRig(const std::string& rig_path, const std::string& path) {
  if (path.empty() || fs::path(path).is_absolute()) return path;
  return (fs::path(rig_path).parent_path() / path).lexically_normal().string();
}

double Number(const YAML::Node& node, const std::string& what) {
  double x = 0.0;
  try {
    x = node.as<double>();
  } catch (const YAML::Exception&) {
    throw DataError(what + " holds a value that is not a number");
  }
  if (!std::isfinite(x)) throw DataError(what + " holds a value that is not finite");
  return x;
}

std::vector<double> Numbers(const YAML::Node& node, std::size_t count, const std::string& what) {
  if (!node.IsSequence() || node.size() != count) {
    throw DataError(what + " must be a list of " + std::to_string(count) + " numbers");
  }
  std::vector<double> values;
  for (const YAML::Node& value : node) values.push_back(Number(value, what));
  return values;
}

// extrinsic: [x y z qx qy qz qw], or rotation: 3x3 rows with translation: [x y z].
SE3d ReadExtrinsic(const YAML::Node& radar, const std::string& what) {
  const bool as_pose = bool(radar["extrinsic"]);
  const bool as_matrix = radar["rotation"] || radar["translation"];
  if (as_pose == as_matrix) {
    throw DataError(what +
                    ": give its mounting once, as extrinsic: [x, y, z, qx, qy, qz, qw] or as rotation: "
                    "(3 rows) with translation: [x, y, z]");
  }
  Eigen::Vector3d t;
  Eigen::Matrix3d R;
  if (as_pose) {
    const std::vector<double> v = Numbers(radar["extrinsic"], 7, what + "'s extrinsic");
    t << v[0], v[1], v[2];
    const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
    if (std::abs(q.norm() - 1.0) > kRotationTolerance) {
      throw DataError(what + "'s extrinsic is not a rotation: its quaternion's norm is " + std::to_string(q.norm()));
    }
    R = q.normalized().toRotationMatrix();
  } else {
    if (!radar["rotation"] || !radar["translation"]) throw DataError(what + ": rotation: and translation: go together");
    const YAML::Node rows = radar["rotation"];
    if (!rows.IsSequence() || rows.size() != 3) throw DataError(what + "'s rotation must be 3 rows of 3 numbers");
    for (int r = 0; r < 3; ++r) {
      const std::vector<double> row = Numbers(rows[std::size_t(r)], 3, what + "'s rotation row");
      R.row(r) << row[0], row[1], row[2];
    }
    const double off = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
    if (off > kRotationTolerance || R.determinant() < 0.0) {
      throw DataError(what + "'s rotation is not a rotation: " +
                      (R.determinant() < 0.0 ? std::string("a reflection (determinant < 0)")
                                             : "R^T R is off the identity by " + std::to_string(off)));
    }
    const std::vector<double> v = Numbers(radar["translation"], 3, what + "'s translation");
    t << v[0], v[1], v[2];
  }
  if (t.norm() > kMaxLeverArm) {
    throw DataError(what + "'s translation is " + std::to_string(t.norm()) + " m from the body's origin (at most " +
                    std::to_string(int(kMaxLeverArm)) + ")");
  }
  return SE3d(SO3d::FromMatrix(R), t);
}

std::string Text(const YAML::Node& node, const std::string& what) {
  if (!node.IsScalar()) throw DataError(what + " must be text");
  return node.as<std::string>();
}

RigRadar ReadRadar(const YAML::Node& node, std::size_t index, const std::string& rig_path, const std::string& bag) {
  const std::string place = "radar " + std::to_string(index + 1);
  if (!node.IsMap()) throw DataError(place + " must be a map of name, scans and mounting");
  static const std::set<std::string> kKeys = {"name",     "sequence",    "topic",       "extrinsic",
                                              "rotation", "translation", "clock_offset"};
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    if (!kKeys.count(key)) throw DataError(place + ": unknown key '" + key + "'");
  }
  RigRadar radar;
  if (!node["name"]) throw DataError(place + " has no name");
  radar.name = Text(node["name"], place + "'s name");
  if (radar.name.empty()) throw DataError(place + " has an empty name");
  const std::string what = "radar '" + radar.name + "'";
  const bool folder = bool(node["sequence"]), topic = bool(node["topic"]);
  if (!folder && !topic) throw DataError(what + " has no scans: give sequence: FOLDER or topic: TOPIC");
  if (folder && topic) throw DataError(what + " has two sources of scans: sequence: or topic:, not both");
  if (folder) radar.scans.sequence_dir = BesideRig(rig_path, Text(node["sequence"], what + "'s sequence"));
  if (topic) {
    if (bag.empty()) throw DataError(what + "'s topic needs the rig's bag: (at the top of the file)");
    radar.scans.bag = bag;
    radar.scans.topic = Text(node["topic"], what + "'s topic");
  }
  radar.body_from_radar = ReadExtrinsic(node, what);
  if (node["clock_offset"]) {
    radar.clock_offset = Number(node["clock_offset"], what + "'s clock_offset");
    if (std::abs(radar.clock_offset) > kMaxRigClockOffset) {
      throw DataError(what + "'s clock_offset " + std::to_string(radar.clock_offset) + " s is past +/-" +
                      std::to_string(kMaxRigClockOffset) + " s");
    }
  }
  return radar;
}

}  // namespace

Rig ReadRig(const std::string& path) {
  const YAML::Node root = ReadYamlDocument(path, "rig");
  try {
    if (!root.IsMap()) throw DataError("a rig file is a map with radars: (and bag:)");
    for (const auto& entry : root) {
      const std::string key = entry.first.as<std::string>();
      if (key != "radars" && key != "bag") throw DataError("unknown key '" + key + "' (radars, bag)");
    }
    const std::string bag = root["bag"] ? BesideRig(path, Text(root["bag"], "bag")) : "";
    const YAML::Node radars = root["radars"];
    if (!radars || !radars.IsSequence() || radars.size() == 0) throw DataError("no radars: (a list of radars)");
    if (radars.size() > kMaxRigRadars) {
      throw DataError(std::to_string(radars.size()) + " radars (at most " + std::to_string(kMaxRigRadars) + ")");
    }
    Rig rig;
    std::set<std::string> names, sources;
    for (std::size_t i = 0; i < radars.size(); ++i) {
      RigRadar radar = ReadRadar(radars[i], i, path, bag);
      if (!names.insert(radar.name).second) throw DataError("two radars are named '" + radar.name + "'");
      const std::string source =
          radar.scans.topic.empty() ? "folder " + radar.scans.sequence_dir : "topic " + radar.scans.topic;
      if (!sources.insert(source).second) {
        throw DataError("radar '" + radar.name + "' reads the " + source + " of another radar");
      }
      rig.radars.push_back(std::move(radar));
    }
    return rig;
  } catch (const DataError& e) {
    throw FileError(path, e.what());
  } catch (const YAML::Exception& e) {
    throw FileError(path, std::string("not a rig: ") + e.what());
  }
}

void WriteRig(const std::string& path, const Rig& rig) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << std::setprecision(17);
    const auto bag =
        std::find_if(rig.radars.begin(), rig.radars.end(), [](const RigRadar& r) { return !r.scans.bag.empty(); });
    if (bag != rig.radars.end()) out << "bag: \"" << bag->scans.bag << "\"\n";
    out << "radars:\n";
    for (const RigRadar& radar : rig.radars) {
      const Eigen::Vector3d& t = radar.body_from_radar.translation();
      const Eigen::Quaterniond& q = radar.body_from_radar.rotation().quaternion();
      out << "  - name: \"" << radar.name << "\"\n";
      if (radar.scans.topic.empty()) {
        out << "    sequence: \"" << radar.scans.sequence_dir << "\"\n";
      } else {
        out << "    topic: \"" << radar.scans.topic << "\"\n";
      }
      out << "    extrinsic: [" << t.x() << ", " << t.y() << ", " << t.z() << ", " << q.x() << ", " << q.y() << ", "
          << q.z() << ", " << q.w() << "]\n";
      out << "    clock_offset: " << radar.clock_offset << "\n";
    }
  });
}

}  // namespace radargauss
