// SPDX-License-Identifier: BSD-3-Clause
// SLAM's outputs (docs/cli.md, "slam") and the map of the place.
#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <system_error>

#include <nlohmann/json.hpp>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/map/pipeline.hpp"
#include "radargauss/slam/radar_slam.hpp"
#include "radargauss/core/stats.hpp"

namespace radargauss {

namespace {

void WriteKeyframes(std::ostream& out, const RadarSlam& slam) {
  out << "keyframe,scan,stamp,path_m,points,x,y,z,qx,qy,qz,qw,describe_ms,search_ms\n" << std::setprecision(9);
  for (std::size_t k = 0; k < slam.keyframes().size(); ++k) {
    const Keyframe& keyframe = slam.keyframes()[k];
    const SE3d& pose = slam.graph().poses()[k];
    const Eigen::Quaterniond& q = pose.rotation().quaternion();
    out << k << ',' << keyframe.scan << ',' << std::fixed << keyframe.stamp << std::defaultfloat << ',' << keyframe.path
        << ',' << keyframe.submap_points << ',' << pose.translation().x() << ',' << pose.translation().y() << ','
        << pose.translation().z() << ',' << q.x() << ',' << q.y() << ',' << q.z() << ',' << q.w() << ','
        << keyframe.describe_ms << ',' << keyframe.search_ms << '\n';
  }
}

void WriteLoops(std::ostream& out, const RadarSlam& slam) {
  out << "query,candidate,injected,score,yaw_deg,verified,overlap,associated,cost,translation_std,rotation_std_deg,"
         "correction_m,correction_deg,accepted,reason\n"
      << std::setprecision(6);
  for (const LoopCandidate& c : slam.candidates()) {
    const LoopCheck& check = c.check;
    out << c.query << ',' << c.candidate << ',' << c.injected << ',' << c.distance << ',' << c.yaw * 180.0 / M_PI << ','
        << c.verified << ',' << check.overlap << ',' << check.associated << ',' << check.cost << ','
        << check.translation_std << ',' << check.rotation_std_deg << ',' << check.correction << ','
        << check.correction_deg << ',' << check.accepted << ",\"" << check.reason << "\"\n";
  }
}

// Each scan's time: whether a keyframe closed, the total, the front end and the back end.
void WriteScanTimes(std::ostream& out, const RadarSlam& slam) {
  out << "scan,stamp,closed_keyframe,total_ms,front_end_ms,back_end_ms\n" << std::setprecision(6);
  const std::vector<OdometryStep>& steps = slam.odometry().steps();
  const std::vector<ScanTime>& times = slam.scan_times();
  for (std::size_t k = 0; k < times.size() && k < steps.size(); ++k) {
    out << k << ',' << std::fixed << std::setprecision(9) << steps[k].stamp << std::defaultfloat << std::setprecision(6)
        << ',' << (times[k].closed_keyframe ? 1 : 0) << ',' << times[k].total_ms() << ',' << times[k].front_end_ms
        << ',' << times[k].back_end_ms << '\n';
  }
}

}  // namespace

namespace {

// The map of the place from its static cloud: the Gaussians, their RCS
// models and the first visits as places.
GaussianMap PlaceMapOf(MapCloud cloud, const RadarSlam& slam) {
  MapOptions options;
  options.gaussians = slam.options().odometry.map.gaussians;
  options.rcs = slam.options().odometry.map.rcs;
  MapGeometry geometry = BuildMapGeometry(std::move(cloud), options);
  FitRcsModels(geometry.map, geometry.cloud, geometry.association, options.rcs);  // as BuildMap
  GaussianMap map = std::move(geometry.map);
  const std::vector<bool>& first_visits = slam.first_visits();
  for (std::size_t k = 0; k < slam.keyframes().size() && k < first_visits.size(); ++k) {
    if (first_visits[k]) map.places.push_back({slam.graph().poses()[k], slam.keyframes()[k].points});
  }
  return map;
}

}  // namespace

GaussianMap BuildPlaceMap(const RadarSlam& slam) {
  if (!slam.options().hold_map_points) throw DataError("the map of the place needs hold_map_points");
  const std::vector<SE3d> poses = slam.Poses();
  std::vector<const StaticScanPoints*> scans;
  std::vector<SE3d> scan_poses;
  for (const PlaceMapPart& part : slam.place_map_parts()) {
    for (std::size_t i = 0; i < part.scans.size(); ++i) {
      scans.push_back(&part.scans[i]);
      scan_poses.push_back(poses[part.first_scan + i]);
    }
  }
  return PlaceMapOf(MergeStaticPoints(scans, scan_poses), slam);
}

GaussianMap BuildPlaceMap(const std::vector<RadarScan>& scans, const RadarSlam& slam) {
  const std::vector<SE3d> poses = slam.Poses();
  if (scans.size() != poses.size()) {
    throw DataError("the map of the place needs the " + std::to_string(poses.size()) +
                    " registered scans in order, not " + std::to_string(scans.size()));
  }
  MapCloudOptions filter;
  filter.ego_velocity = slam.options().odometry.ego_velocity;
  return PlaceMapOf(BuildMapCloud(scans, poses, filter), slam);
}

SlamSummary Summarise(const RadarSlam& slam) {
  SlamSummary s;
  s.keyframes = slam.keyframes().size();
  s.compared = slam.candidates().size();
  for (const LoopCandidate& c : slam.candidates()) {
    s.verified += c.verified;
    s.loops += c.check.accepted && !c.injected;
    s.injected += c.injected;
  }
  std::vector<double> describe, search, keyframe_ms;
  for (const Keyframe& keyframe : slam.keyframes()) {
    describe.push_back(keyframe.describe_ms);
    search.push_back(keyframe.search_ms);
    keyframe_ms.push_back(keyframe.back_end_ms());
  }
  s.describe_ms = Median(describe);
  s.search_ms = Median(search);
  s.asynchronous = slam.asynchronous();
  if (!keyframe_ms.empty()) {
    std::sort(keyframe_ms.begin(), keyframe_ms.end());
    s.keyframe_median_ms = MedianOfSorted(keyframe_ms);
    s.keyframe_p99_ms = PercentileOfSorted(keyframe_ms, 0.99);
    s.keyframe_max_ms = keyframe_ms.back();
  }
  std::vector<double> total, back_end;
  for (const ScanTime& t : slam.scan_times()) {
    total.push_back(t.total_ms());
    back_end.push_back(t.back_end_ms);
  }
  if (!total.empty()) {
    std::sort(total.begin(), total.end());
    std::sort(back_end.begin(), back_end.end());
    s.total_median_ms = MedianOfSorted(total);
    s.total_p90_ms = PercentileOfSorted(total, 0.9);
    s.total_p99_ms = PercentileOfSorted(total, 0.99);
    s.total_max_ms = total.back();
    s.back_end_median_ms = MedianOfSorted(back_end);
    s.back_end_p90_ms = PercentileOfSorted(back_end, 0.9);
    s.back_end_p99_ms = PercentileOfSorted(back_end, 0.99);
    s.back_end_max_ms = back_end.back();
  }
  return s;
}

void WriteSlam(const std::string& dir, const RadarSlam& slam) {
  namespace fs = std::filesystem;
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) throw FileError(dir, "cannot create the output folder: " + error.message());
  const fs::path out(dir);
  WriteTum((out / "slam.tum").string(), slam.trajectory());
  WriteFileAtomically((out / "keyframes.csv").string(), [&](std::ostream& s) { WriteKeyframes(s, slam); });
  WriteFileAtomically((out / "loops.csv").string(), [&](std::ostream& s) { WriteLoops(s, slam); });
  WriteFileAtomically((out / "per_scan.csv").string(), [&](std::ostream& s) { WriteScanTimes(s, slam); });
  const SlamSummary s = Summarise(slam);
  nlohmann::json summary = {{"keyframes", s.keyframes},           {"candidates_compared", s.compared},
                            {"candidates_verified", s.verified},  {"loops", s.loops},
                            {"injected_false_loops", s.injected}, {"describe_time_ms", s.describe_ms},
                            {"search_time_ms", s.search_ms}};
  summary["scan_time_ms"] = {
      {"median", s.total_median_ms}, {"p90", s.total_p90_ms}, {"p99", s.total_p99_ms}, {"max", s.total_max_ms}};
  summary["back_end_time_ms"] = {{"median", s.back_end_median_ms},
                                 {"p90", s.back_end_p90_ms},
                                 {"p99", s.back_end_p99_ms},
                                 {"max", s.back_end_max_ms}};
  summary["asynchronous_back_end"] = s.asynchronous;
  summary["keyframe_back_end_ms"] = {
      {"median", s.keyframe_median_ms}, {"p99", s.keyframe_p99_ms}, {"max", s.keyframe_max_ms}};
  WriteFileAtomically((out / "slam.json").string(), [&](std::ostream& stream) { stream << summary.dump(2) << "\n"; });
}

}  // namespace radargauss
