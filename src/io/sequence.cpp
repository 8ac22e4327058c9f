// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/sequence.hpp"

#include <algorithm>
#include <functional>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "radargauss/core/error.hpp"
#include "radargauss/io/kitti_bin.hpp"
#include "radargauss/io/pcd.hpp"
#include "radargauss/core/read_file.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/io/rosbag.hpp"

namespace radargauss {

namespace fs = std::filesystem;

SE3d SnailRadar20231213Extrinsic() {
  Eigen::Matrix3d R_body_xt32;
  R_body_xt32 << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  Eigen::Matrix3d R_x36d_xt32;
  R_x36d_xt32 << -0.001402106, -0.999967799, 0.007901562,  //
      0.999997759, -0.001414596, -0.001575345,             //
      0.001586472, 0.007899336, 0.999967541;
  Eigen::Matrix3d R_x36d_ars548;
  R_x36d_ars548 << 0.99912647794293, 0.039117559886893, -0.0147002578838332,  //
      -0.0390210149947843, 0.999215265264576, 0.00679809171902766,            //
      0.0149546468407877, -0.00621853445265288, 0.999868835581512;
  const Eigen::Matrix3d R_body_x36d = R_body_xt32 * R_x36d_xt32.transpose();
  const Eigen::Matrix3d R_body_ars548 = R_body_x36d * R_x36d_ars548;
  const SE3d T_body_xt32(SO3d::FromMatrix(R_body_xt32), Eigen::Vector3d::Zero());
  const SE3d T_body_ars548(SO3d::FromMatrix(R_body_ars548), Eigen::Vector3d(0.0, 0.0, 0.07));
  return T_body_xt32.Inverse() * T_body_ars548;
}

Trajectory ReadRadarTrajectory(const std::string& ground_truth, const SE3d& extrinsic) {
  // "BAG:/topic[:child_frame]": the poses of a ROS 2 bag's topic.
  const std::size_t colon = ground_truth.find(":/");
  std::error_code error;
  if (colon != std::string::npos && !std::filesystem::exists(ground_truth, error)) {
    if (colon == 0) throw DataError("'" + Printable(ground_truth) + "': no bag before ':/' (BAG:/topic[:child_frame])");
    const std::string topic_and_child = ground_truth.substr(colon + 1);
    const std::size_t child = topic_and_child.find(':');
    return ReadBagPoses(ground_truth.substr(0, colon), topic_and_child.substr(0, child),
                        child == std::string::npos ? "" : topic_and_child.substr(child + 1))
        .RightMultiplied(extrinsic);
  }
  const Trajectory trajectory = ReadTum(ground_truth);
  if (trajectory.size() < 2) throw FileError(ground_truth, "needs at least 2 poses");
  return trajectory.RightMultiplied(extrinsic);
}

SE3d ResolveExtrinsic(const std::string& spec, const std::string& ground_truth_path) {
  if (spec == "identity") return SE3d();
  if (spec == "snail-20231213") return SnailRadar20231213Extrinsic();
  if (spec == "auto") {
    const std::string name = fs::path(ground_truth_path).filename().string();
    return name.find("xt32") != std::string::npos ? SnailRadar20231213Extrinsic() : SE3d();
  }
  std::error_code error;
  if (!std::filesystem::exists(spec, error)) {
    throw FileError(spec, "not an extrinsic preset (identity, snail-20231213, auto) nor a readable file");
  }
  return ReadExtrinsicFile(spec);
}

SE3d ReadExtrinsicFile(const std::string& path) { return ReadStatedExtrinsicFile(path).pose; }

namespace {

// The numbers of `line`'s words after the first `skip`, each finite; `what` names them in errors.
std::vector<double> ExtrinsicNumbers(const std::string& line, std::size_t skip, std::size_t count,
                                     const std::string& what, const std::string& path) {
  std::istringstream tokens(line);
  std::string word;
  for (std::size_t k = 0; k < skip; ++k) tokens >> word;
  std::vector<double> values;
  while (tokens >> word) {
    char* end = nullptr;
    const double value = std::strtod(word.c_str(), &end);
    if (*end != '\0') throw FileError(path, "extrinsic holds '" + Printable(word) + "', not a number");
    if (!std::isfinite(value)) throw FileError(path, "extrinsic holds " + word + ", a value that is not finite");
    values.push_back(value);
  }
  if (values.size() < count) throw FileError(path, "extrinsic needs '" + what + "'");
  if (values.size() > count) {
    throw FileError(path, "extrinsic needs exactly " + std::to_string(count) + " numbers" +
                              (skip > 0 ? " in '" + what + "'" : std::string()));
  }
  return values;
}

}  // namespace

StatedExtrinsic ReadStatedExtrinsicFile(const std::string& path) {
  std::istringstream in(ReadFileBytes(path, "pose file (extrinsic)", 1 << 16));
  std::optional<StatedExtrinsic> stated;
  std::string line;
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    if (!stated) {
      const std::vector<double> v = ExtrinsicNumbers(line, 0, 7, "x y z qx qy qz qw", path);
      if (Eigen::Vector3d(v[0], v[1], v[2]).norm() > kMaxLeverArm) {
        throw FileError(path, "extrinsic's translation is past " + std::to_string(int(kMaxLeverArm)) +
                                  " m (a sensor's mounting on its vehicle)");
      }
      const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
      if (std::abs(q.norm() - 1.0) > kTumQuaternionNormTolerance) {
        throw FileError(path, "extrinsic quaternion is not unit");
      }
      stated = StatedExtrinsic{SE3d(SO3d(q), Eigen::Vector3d(v[0], v[1], v[2])), std::nullopt};
    } else if (line.compare(first, 4, "std ") == 0 || line.compare(first, 4, "std\t") == 0) {
      if (stated->accuracy) throw FileError(path, "extrinsic states its accuracy twice");
      const std::vector<double> v =
          ExtrinsicNumbers(line.substr(first), 1, 3, "std <rotation deg> <translation m> <clock offset s>", path);
      if (v[0] < 0.0 || v[1] < 0.0 || v[2] < 0.0 || v[0] > 180.0 || v[1] > kMaxLeverArm || v[2] > 1.0) {
        throw FileError(path, "extrinsic's stds must be 0 to 180 deg, 0 to " + std::to_string(int(kMaxLeverArm)) +
                                  " m and 0 to 1 s");
      }
      stated->accuracy = ExtrinsicAccuracy{v[0], v[1], v[2]};
    }
  }
  if (!stated) throw FileError(path, "extrinsic file is empty");
  return *stated;
}

namespace {

// Files with `extension` directly in `dir`, sorted by the time in their name
// when all have one, else by name.
std::vector<std::string> ListScanFiles(const fs::path& dir, const std::string& extension) {
  std::vector<std::pair<double, std::string>> files;
  bool all_timed = true;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file() || entry.path().extension() != extension) continue;
    double time = 0.0;
    all_timed = TimestampFromFileName(entry.path().string(), time) && all_timed;
    files.emplace_back(time, entry.path().string());
  }
  if (all_timed) {
    std::sort(files.begin(), files.end());
  } else {
    std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  }
  std::vector<std::string> paths;
  for (auto& file : files) paths.push_back(std::move(file.second));
  return paths;
}

bool HasFilesWith(const fs::path& dir, const std::string& extension) {
  std::error_code error;
  if (!fs::is_directory(dir, error)) return false;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file() && entry.path().extension() == extension) return true;
  }
  return false;
}

// Where a sequence folder keeps its scans, and in which layout.
struct ScanFolder {
  fs::path path;
  std::string extension;
  std::string layout;
};

ScanFolder FindScanFolder(const std::string& sequence_dir) {
  const fs::path dir(sequence_dir);
  std::error_code error;
  if (!fs::is_directory(dir, error)) throw FileError(sequence_dir, "not a directory");
  if (HasFilesWith(dir / "ars548" / "points", ".pcd")) return {dir / "ars548" / "points", ".pcd", "snail-radar"};
  if (HasFilesWith(dir, ".pcd")) return {dir, ".pcd", "pcd-folder"};
  if (HasFilesWith(dir, ".bin")) return {dir, ".bin", "bin-folder"};
  // A data set's root often holds its scans one folder down.
  for (const char* sub : {"points", "pcd", "scans", "radar"}) {
    if (HasFilesWith(dir / sub, ".pcd") || HasFilesWith(dir / sub, ".bin")) {
      throw FileError(sequence_dir, "no scans found here; did you mean " + (dir / sub).string() + "?");
    }
  }
  throw FileError(sequence_dir, "no scans found (expected ars548/points/*.pcd, *.pcd or *.bin)");
}

}  // namespace

std::string ForEachScan(const SequenceOptions& options,
                        const std::function<bool(RadarScan&, const std::string&)>& visit) {
  if (!(std::abs(options.elevation_bias_deg) < 45.0)) throw DataError("the elevation bias must be within +/-45 deg");
  const double elevation_bias = options.elevation_bias_deg * M_PI / 180.0;
  bool first = true;
  double last_time = 0.0;
  // Each scan as LoadSequence holds it: its elevation bias removed, its time after the last's.
  const auto deliver = [&](RadarScan& scan, const std::string& source) {
    if (!first && !(scan.timestamp > last_time)) {
      throw FileError(source, "scan time does not increase (missing or repeated timestamps)");
    }
    first = false;
    last_time = scan.timestamp;
    if (elevation_bias != 0.0) LowerElevations(scan, elevation_bias);
    return visit(scan, source);
  };
  if (!options.bag.empty()) {
    if (options.topic.empty()) throw FileError(options.bag, "a bag needs --topic");
    ForEachBagScan(options.bag, options.topic, options.fields, deliver);
    return "rosbag";
  }
  if (options.sequence_dir.empty()) throw DataError("no sequence given (--sequence DIR or --bag FILE)");
  const ScanFolder folder = FindScanFolder(options.sequence_dir);
  std::vector<std::string> layout;
  if (folder.extension == ".bin") {
    try {
      layout = ParseBinLayout(options.bin_layout);
    } catch (const std::invalid_argument& e) {
      throw DataError(e.what());
    }
  }
  for (const std::string& path : ListScanFiles(folder.path, folder.extension)) {
    RadarScan scan =
        folder.extension == ".pcd" ? ReadPcdScan(path, options.fields) : ReadKittiBin(path, layout, options.fields);
    if (!deliver(scan, path)) break;
  }
  return folder.layout;
}

Sequence LoadSequence(const SequenceOptions& options) {
  Sequence sequence;
  std::vector<RadarScan> scans;
  std::vector<std::string> sources;
  sequence.layout = ForEachScan(options, [&](RadarScan& scan, const std::string& source) {
    scans.push_back(std::move(scan));
    sources.push_back(source);
    return true;
  });
  sequence.total_scans = scans.size();
  if (scans.empty()) throw DataError("sequence has no scans");

  if (options.ground_truth.empty()) {
    ResolveExtrinsic(options.extrinsic, "");  // a file given is checked though no reference uses it
    sequence.scans = std::move(scans);
    sequence.scan_sources = std::move(sources);
    return sequence;
  }
  sequence.extrinsic = ResolveExtrinsic(options.extrinsic, options.ground_truth);
  sequence.trajectory = ReadRadarTrajectory(options.ground_truth, sequence.extrinsic);
  for (std::size_t i = 0; i < scans.size(); ++i) {
    const std::optional<SE3d> pose = sequence.trajectory.Interpolate(scans[i].timestamp);
    if (!pose) {
      ++sequence.skipped_scans;
      continue;
    }
    sequence.poses.push_back(*pose);
    sequence.scans.push_back(std::move(scans[i]));
    sequence.scan_sources.push_back(sources[i]);
  }
  if (sequence.scans.empty()) {
    throw FileError(options.ground_truth, "no scan time lies within the trajectory's time span");
  }
  return sequence;
}

}  // namespace radargauss
