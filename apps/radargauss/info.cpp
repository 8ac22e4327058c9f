// SPDX-License-Identifier: BSD-3-Clause
// radargauss info: summarise a sequence and an IMU file, or list a bag's topics.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "commands.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/rig_twist.hpp"
#include "radargauss/io/imu.hpp"
#include "radargauss/io/rig.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/core/stats.hpp"

namespace radargauss::cli {

namespace {

struct Range {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  void Add(double v) {
    min = std::min(min, v);
    max = std::max(max, v);
  }
};

// Every topic: type, count, rate over its span and the span (record times).
int ListTopics(const std::string& bag) {
  std::printf("bag: %s\n", bag.c_str());
  for (const BagTopic& topic : ListBagTopics(bag)) {
    const double span = topic.last - topic.first;
    const double rate = topic.messages > 1 && span > 0.0 ? double(topic.messages - 1) / span : 0.0;
    std::printf("  %-40s %-32s %8zu messages %9.2f Hz  %.3f .. %.3f s (%.3f s)\n", Printable(topic.name).c_str(),
                Printable(topic.type).c_str(), topic.messages, rate, topic.first, topic.last, span);
  }
  return 0;
}

struct InfoSettings {
  SequenceOptions sequence;
  std::string rig;
  std::string imu;
  std::string imu_topic;  // a sensor_msgs/Imu topic of --bag
};

// An IMU's span, rate, gaps and mean rates (io/imu.hpp).
void PrintImu(const std::vector<ImuSample>& samples) {
  const ImuSummary s = SummariseImu(samples);
  std::printf(
      "imu: %zu samples, %.9f .. %.9f (%.3f s), %.1f Hz (median interval), %zu gaps over 3 intervals, "
      "longest %.4f s\n",
      s.samples, s.start, s.end, s.end - s.start, s.rate_hz, s.gaps, s.max_gap);
  std::printf("imu mean: angular rate %.5f %.5f %.5f rad/s, specific force %.4f %.4f %.4f m/s^2 (norm %.4f)\n",
              s.mean_angular_velocity.x(), s.mean_angular_velocity.y(), s.mean_angular_velocity.z(),
              s.mean_specific_force.x(), s.mean_specific_force.y(), s.mean_specific_force.z(),
              s.mean_specific_force.norm());
}

// Each radar of a rig: its scans, their span and rate, its mounting and
// clock; then which rotations the rig's Doppler cannot observe.
int RigInfo(const std::string& path) {
  const Rig rig = ReadRig(path);
  std::printf("rig: %s, %zu radars\n", path.c_str(), rig.radars.size());
  std::vector<SE3d> mountings;
  for (const RigRadar& radar : rig.radars) {
    Sequence sequence;
    try {
      sequence = LoadSequence(radar.scans);
    } catch (const DataError& e) {
      throw DataError("radar '" + radar.name + "': " + e.what());
    }
    std::vector<double> counts;
    for (const RadarScan& scan : sequence.scans) counts.push_back(double(scan.points.size()));
    const double first = sequence.scans.front().timestamp, last = sequence.scans.back().timestamp;
    const double rate = last > first ? double(sequence.scans.size() - 1) / (last - first) : 0.0;
    const Eigen::Vector3d& t = radar.body_from_radar.translation();
    const Eigen::Matrix3d R = radar.body_from_radar.rotation().Matrix();  // R = Rz(yaw) Ry(pitch) Rx(roll)
    const Eigen::Vector3d rpy =
        Eigen::Vector3d(std::atan2(R(2, 1), R(2, 2)), -std::asin(std::clamp(R(2, 0), -1.0, 1.0)),
                        std::atan2(R(1, 0), R(0, 0))) *
        180.0 / M_PI;
    std::printf(
        "  %s: %zu scans (%s), %.3f .. %.3f s, %.1f Hz, median %.0f points; at %.3f %.3f %.3f m, "
        "roll/pitch/yaw %.2f %.2f %.2f deg; clock offset %.4f s\n",
        Printable(radar.name).c_str(), sequence.scans.size(), sequence.layout.c_str(), first - radar.clock_offset,
        last - radar.clock_offset, rate, Median(counts), t.x(), t.y(), t.z(), rpy.x(), rpy.y(), rpy.z(),
        radar.clock_offset);
    mountings.push_back(radar.body_from_radar);
  }
  const Eigen::Matrix3Xd unobserved = UnobservedRotations(mountings);
  if (unobserved.cols() == 0) {
    std::printf("doppler observes: the body's velocity and angular velocity (lever arms not on one line)\n");
  } else if (unobserved.cols() == 1) {
    std::printf("doppler observes: all but the rotation about the line through the radars (%.3f %.3f %.3f)\n",
                unobserved(0, 0), unobserved(1, 0), unobserved(2, 0));
  } else {
    std::printf("doppler observes: each radar's velocity, not the angular velocity (the radars share one place)\n");
  }
  return 0;
}

int RunInfo(const InfoSettings& settings) {
  const SequenceOptions& options = settings.sequence;
  if (!settings.rig.empty()) {
    if (!options.sequence_dir.empty() || !options.bag.empty()) {
      throw DataError("--rig names the radars' scans itself: drop --sequence and --bag");
    }
    return RigInfo(settings.rig);
  }
  if (!settings.imu.empty()) {
    PrintImu(ReadImuFile(settings.imu));
    if (options.sequence_dir.empty() && options.bag.empty()) return 0;
  }
  if (!settings.imu_topic.empty()) {
    if (options.bag.empty()) throw DataError("--imu-topic needs --bag");
    PrintImu(ReadBagImu(options.bag, settings.imu_topic, false));
    if (options.topic.empty()) return 0;
  }
  if (!options.bag.empty() && options.topic.empty()) return ListTopics(options.bag);
  const Sequence sequence = LoadSequence(options);
  std::vector<double> counts;
  Range doppler, rcs;
  bool has_doppler = true, has_rcs = true, has_std = true;
  for (const RadarScan& scan : sequence.scans) {
    counts.push_back(double(scan.points.size()));
    has_doppler = has_doppler && scan.has_doppler;
    has_rcs = has_rcs && scan.has_rcs;
    for (const RadarPoint& p : scan.points) {
      doppler.Add(p.doppler);
      rcs.Add(p.rcs);
      has_std = has_std && p.std_dev.has_value();
    }
  }
  const auto [fewest, most] = std::minmax_element(counts.begin(), counts.end());
  std::printf("layout: %s\n", sequence.layout.c_str());
  std::printf("scans: %zu read", sequence.total_scans);
  if (!options.ground_truth.empty()) {
    std::printf(", %zu matched to poses, %zu outside the trajectory's time span", sequence.scans.size(),
                sequence.skipped_scans);
  }
  std::printf("\npoints per scan: min %zu, median %.1f, max %zu\n", std::size_t(*fewest), Median(counts),
              std::size_t(*most));
  std::printf("fields: xyz%s%s%s\n", has_doppler ? " doppler" : "", has_rcs ? " rcs" : "", has_std ? " stds" : "");
  std::printf("time span: %.9f .. %.9f (%.3f s)\n", sequence.scans.front().timestamp, sequence.scans.back().timestamp,
              sequence.scans.back().timestamp - sequence.scans.front().timestamp);
  if (has_doppler) std::printf("doppler: %.3f .. %.3f m/s\n", doppler.min, doppler.max);
  if (has_rcs) std::printf("rcs: %.3f .. %.3f dBsm\n", rcs.min, rcs.max);
  if (!sequence.poses.empty()) {
    double length = 0.0;
    for (std::size_t i = 1; i < sequence.poses.size(); ++i) {
      length += (sequence.poses[i].translation() - sequence.poses[i - 1].translation()).norm();
    }
    std::printf("trajectory: %zu poses, %.1f m driven over the matched scans\n", sequence.trajectory.size(), length);
  }
  return 0;
}

}  // namespace

Subcommand AddInfo(CLI::App& parent) {
  auto settings = std::make_shared<InfoSettings>();
  CLI::App* app = parent.add_subcommand("info", "Summarise a sequence, a rig and an IMU file (or list a bag's topics)");
  AddSequenceOptions(app, settings->sequence);
  app->add_option("--rig", settings->rig,
                  "Rig file (radars, their scans, mountings and clocks): each radar's scans, and what the rig's "
                  "Doppler observes");
  app->add_option("--imu", settings->imu, "IMU file of lines 'stamp wx wy wz ax ay az': its rate, gaps, mean rates");
  app->add_option("--imu-topic", settings->imu_topic, "sensor_msgs/Imu topic of --bag: its rate, gaps, mean rates");
  return {app, [settings] { return RunInfo(*settings); }};
}

}  // namespace radargauss::cli
