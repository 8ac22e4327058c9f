// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/experiment/run_mcap.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"
#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/map/map_file.hpp"
#include "radargauss/core/trajectory.hpp"

namespace radargauss {

namespace {

namespace fs = std::filesystem;

// A cloud of one row from columns of doubles, named.
PointCloud2Data CloudOf(const std::vector<std::string>& names, const std::vector<std::vector<double>>& columns) {
  PointCloud2Data cloud;
  for (std::size_t i = 0; i < names.size(); ++i) cloud.fields.push_back({names[i], std::uint32_t(8 * i), 8, 1});
  cloud.point_step = std::uint32_t(8 * names.size());
  cloud.width = std::uint32_t(columns.empty() ? 0 : columns[0].size());
  cloud.row_step = cloud.width * cloud.point_step;
  cloud.data.resize(cloud.row_step);
  for (std::size_t p = 0; p < cloud.width; ++p) {
    for (std::size_t f = 0; f < names.size(); ++f) {
      std::memcpy(cloud.data.data() + p * cloud.point_step + 8 * f, &columns[f][p], 8);  // little-endian hosts
    }
  }
  return cloud;
}

// The Gaussian as a sphere marker scaled and turned to its ellipsoid at `sigma`.
Ros2Marker Ellipsoid(const Gaussian& g, double sigma, std::int32_t id, const Ros2Header& header) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(g.covariance);
  Eigen::Matrix3d axes = eigen.eigenvectors();
  if (axes.determinant() < 0.0) axes.col(2) = -axes.col(2);
  Ros2Marker m;
  m.header = header;
  m.ns = "gaussians";
  m.id = id;
  m.type = 2;  // SPHERE: scale is the diameter along each axis
  m.pose = SE3d(SO3d(Eigen::Quaterniond(axes)), g.mean);
  m.scale = 2.0 * sigma * eigen.eigenvalues().cwiseMax(1e-8).cwiseSqrt();
  m.color = Eigen::Vector4f(0.2f, 0.6f, 1.0f, 0.35f);
  return m;
}

}  // namespace

void WriteRunMcap(const std::string& path, const RunForViewer& run, const RunMcapOptions& options) {
  if (run.stamps.size() != run.poses.size() || run.reference_stamps.size() != run.reference.size() ||
      (!run.scans.empty() && run.scans.size() != run.poses.size())) {
    throw std::invalid_argument("WriteRunMcap: stamps, poses and scans differ in count");
  }
  if (!(options.ellipsoid_sigma > 0.0) || !(options.ellipsoid_sigma <= kMaxEllipsoidSigma)) {
    throw std::invalid_argument("WriteRunMcap: ellipsoid_sigma must be in (0, " +
                                std::to_string(int(kMaxEllipsoidSigma)) + "], not " +
                                std::to_string(options.ellipsoid_sigma));
  }
  WriteFileAtomically(
      path,
      [&](std::ostream& out) {
        McapWriter writer(out, options.mcap);
        const auto topic = [&](const std::string& name, const std::string& type) {
          return writer.AddChannel(name, writer.AddSchema(type, "ros2msg", Ros2MessageDefinition(type)));
        };
        const std::uint16_t pose = topic("/radar/pose", "geometry_msgs/msg/PoseStamped");
        const std::uint16_t tf = topic("/tf", "tf2_msgs/msg/TFMessage");
        const std::uint16_t registered =
            run.scans.empty() ? 0 : topic("/radar/registered", "sensor_msgs/msg/PointCloud2");
        for (std::size_t k = 0; k < run.poses.size(); ++k) {
          const std::uint64_t at = std::uint64_t(StampNanoseconds(run.stamps[k]));
          writer.Write(pose, at, at, EncodeRos2PoseStamped({run.stamps[k], "map"}, run.poses[k]));
          writer.Write(tf, at, at, EncodeRos2Transform({run.stamps[k], "map"}, "radar", run.poses[k]));
          if (run.scans.empty()) continue;
          RadarScan in_map = run.scans[k];
          for (RadarPoint& p : in_map.points) p.position = run.poses[k] * p.position;
          writer.Write(registered, at, at, EncodeRos2PointCloud2({run.stamps[k], "map"}, EncodePointCloud2(in_map)));
        }
        // Once, at the end: the paths, the map and the loops.
        const double end = run.stamps.empty() ? 0.0 : run.stamps.back();
        const std::uint64_t at = std::uint64_t(StampNanoseconds(end));
        writer.Write(topic("/trajectory", "nav_msgs/msg/Path"), at, at,
                     EncodeRos2Path({end, "map"}, run.stamps, run.poses));
        if (!run.reference.empty()) {
          writer.Write(topic("/reference/trajectory", "nav_msgs/msg/Path"), at, at,
                       EncodeRos2Path({end, "map"}, run.reference_stamps, run.reference));
        }
        if (!run.map.gaussians.empty()) {
          std::vector<std::vector<double>> columns(5);
          for (const Gaussian& g : run.map.gaussians) {
            for (int i = 0; i < 3; ++i) columns[i].push_back(g.mean(i));
            columns[3].push_back(g.rcs.median);
            columns[4].push_back(double(g.point_count));
          }
          writer.Write(topic("/map/gaussians", "sensor_msgs/msg/PointCloud2"), at, at,
                       EncodeRos2PointCloud2({end, "map"}, CloudOf({"x", "y", "z", "rcs", "members"}, columns)));
          // The best-supported Gaussians first, up to the limit.
          std::vector<std::size_t> order(run.map.gaussians.size());
          for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
          std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
            return run.map.gaussians[a].point_count > run.map.gaussians[b].point_count;
          });
          order.resize(std::min(order.size(), options.max_ellipsoids));
          std::vector<Ros2Marker> ellipsoids;
          for (const std::size_t i : order) {
            ellipsoids.push_back(Ellipsoid(run.map.gaussians[i], options.ellipsoid_sigma,
                                           std::int32_t(ellipsoids.size()), {end, "map"}));
          }
          writer.Write(topic("/map/ellipsoids", "visualization_msgs/msg/MarkerArray"), at, at,
                       EncodeRos2MarkerArray(ellipsoids));
        }
        if (!run.loops.empty()) {
          Ros2Marker lines;
          lines.header = {end, "map"};
          lines.ns = "loops";
          lines.type = 5;  // LINE_LIST
          lines.scale = Eigen::Vector3d(0.3, 0.0, 0.0);
          lines.color = Eigen::Vector4f(1.0f, 0.3f, 0.1f, 1.0f);
          for (const auto& [a, b] : run.loops) lines.points.insert(lines.points.end(), {a, b});
          writer.Write(topic("/loops", "visualization_msgs/msg/MarkerArray"), at, at, EncodeRos2MarkerArray({lines}));
        }
        writer.Finish();
      },
      true);
}

namespace {

// The cells of the CSV line bytes[begin, end) into `cells` (quotes group
// commas and are dropped), reusing the strings it already holds.
void SplitCsvLine(const std::string& bytes, std::size_t begin, std::size_t end, std::vector<std::string>& cells,
                  std::size_t& count) {
  count = 0;
  bool quoted = false;
  const auto next_cell = [&] {
    if (count == cells.size()) cells.emplace_back();
    cells[count++].clear();
  };
  next_cell();
  for (std::size_t i = begin; i < end; ++i) {
    const char c = bytes[i];
    if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      next_cell();
    } else {
      cells[count - 1] += c;
    }
  }
}

// The columns `names` of a CSV file with a header, as numbers, read line by
// line into one vector per column, the cells' strings reused from line to
// line: a file of millions of rows costs its numbers, not a map per row.
std::vector<std::vector<double>> ReadCsvColumns(const std::string& path, const std::vector<std::string>& names) {
  const std::string bytes = ReadFileBytes(path, "CSV file", std::size_t(1) << 30);
  std::vector<std::size_t> wanted;
  std::vector<std::string> cells;
  std::size_t columns = 0, count = 0, number = 0;
  std::vector<std::vector<double>> values(names.size());
  for (std::size_t begin = 0; begin < bytes.size();) {
    std::size_t end = bytes.find('\n', begin);
    if (end == std::string::npos) end = bytes.size();
    SplitCsvLine(bytes, begin, end, cells, count);
    begin = end + 1;
    ++number;
    if (number == 1) {
      columns = count;
      for (const std::string& name : names) {
        const auto found = std::find(cells.begin(), cells.begin() + std::ptrdiff_t(count), name);
        if (found == cells.begin() + std::ptrdiff_t(count)) throw FileError(path, "no column '" + name + "'");
        wanted.push_back(std::size_t(found - cells.begin()));
      }
      continue;
    }
    if (count != columns) throw FileError(path, number, "expected " + std::to_string(columns) + " columns");
    for (std::size_t c = 0; c < names.size(); ++c) {
      const std::string& cell = cells[wanted[c]];
      char* after = nullptr;
      const double value = cell.empty() ? NAN : std::strtod(cell.c_str(), &after);
      if (cell.empty() || *after != '\0' || !std::isfinite(value)) {
        throw FileError(path, number, "column '" + names[c] + "' holds '" + Printable(cell) + "', not a number");
      }
      values[c].push_back(value);
    }
  }
  if (number == 0) throw FileError(path, "no header");
  return values;
}

}  // namespace

RunForViewer ReadRunFolder(const std::string& folder) {
  const fs::path dir(folder);
  std::error_code error;
  if (!fs::is_directory(dir, error)) throw FileError(folder, "not a results folder");
  RunForViewer run;
  std::string trajectory;
  for (const char* name : {"slam.tum", "odometry.tum", "relocalization.tum"}) {
    if (fs::exists(dir / name, error)) {
      trajectory = (dir / name).string();
      break;
    }
  }
  if (trajectory.empty()) throw FileError(folder, "no slam.tum, odometry.tum or relocalization.tum");
  const Trajectory poses = ReadTum(trajectory);
  for (const StampedPose& p : poses) {
    run.stamps.push_back(p.time);
    run.poses.push_back(p.pose);
  }
  if (fs::exists(dir / "map.rgm", error)) run.map = ReadMap((dir / "map.rgm").string());
  if (fs::exists(dir / "loops.csv", error) && fs::exists(dir / "keyframes.csv", error)) {
    const std::string keyframes_path = (dir / "keyframes.csv").string(), loops_path = (dir / "loops.csv").string();
    const std::vector<double> keyframe_stamps = ReadCsvColumns(keyframes_path, {"stamp"})[0];
    const auto position = [&](double index) -> Eigen::Vector3d {
      if (!(index >= 0.0) || index >= double(keyframe_stamps.size())) {
        throw FileError(loops_path, "a loop names keyframe " + std::to_string(index) + ", which keyframes.csv lacks");
      }
      const std::optional<SE3d> pose = poses.Interpolate(keyframe_stamps[std::size_t(index)]);
      if (!pose) throw FileError(loops_path, "a loop's keyframe lies outside the trajectory");
      return pose->translation();
    };
    const std::vector<std::vector<double>> loops = ReadCsvColumns(loops_path, {"accepted", "query", "candidate"});
    for (std::size_t k = 0; k < loops[0].size(); ++k) {
      if (loops[0][k] != 0.0) run.loops.emplace_back(position(loops[1][k]), position(loops[2][k]));
    }
  }
  return run;
}

}  // namespace radargauss
