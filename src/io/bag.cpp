// SPDX-License-Identifier: BSD-3-Clause
// Bags of every kind behind one API (io/rosbag.hpp): ROS1 through its
// library, ROS 2 through io/rosbag2.hpp and the CDR messages.
#include "radargauss/core/error.hpp"
#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/io/rosbag2.hpp"

namespace radargauss {

namespace {

std::string SourceOf(const std::string& bag, const Ros2Message& m, std::size_t index) {
  return bag + ":" + *m.topic + "#" + std::to_string(index);
}

void RequireType(const Ros2Message& m, const std::string& source, const char* package, const char* name) {
  if (!IsRosType(*m.type, package, name)) {
    throw FileError(source, "message is " + Printable(*m.type) + ", not " + package + "/msg/" + name);
  }
}

}  // namespace

void AppendBagImuSample(std::vector<ImuSample>& samples, const ImuSample& sample, const std::string& source) {
  if (!sample.angular_velocity.allFinite()) throw FileError(source, "angular velocity is not finite");
  if (!sample.specific_force.allFinite()) throw FileError(source, "linear acceleration is not finite");
  const std::string fault = ImuSampleFault(sample);
  if (!fault.empty()) throw FileError(source, fault);
  if (!samples.empty() && !(sample.stamp > samples.back().stamp)) {
    throw FileError(source, "stamp " + std::to_string(sample.stamp) + " s is not after the previous message's");
  }
  samples.push_back(sample);
}

std::vector<BagTopic> ListBagTopics(const std::string& bag_path) {
  if (DetectBagFormat(bag_path) == BagFormat::kRos1) return ListRos1BagTopics(bag_path);
  return ListRos2Topics(bag_path);
}

std::vector<RadarScan> ReadBagScans(const std::string& bag_path, const std::string& topic,
                                    const FieldMapping& mapping) {
  if (DetectBagFormat(bag_path) == BagFormat::kRos1) return ReadRos1BagScans(bag_path, topic, mapping);
  std::vector<RadarScan> scans;
  PointCloud2Data cloud;
  ForEachRos2Message(bag_path, topic, [&](const Ros2Message& m) {
    const std::string source = SourceOf(bag_path, m, scans.size());
    RequireType(m, source, "sensor_msgs", "PointCloud2");
    const Ros2Header header = DecodeRos2PointCloud2(m.data, m.size, source, cloud);
    const double stamp = header.stamp != 0.0 ? header.stamp : double(m.log_time) * 1e-9;
    scans.push_back(DecodePointCloud2(cloud, stamp, mapping, source));
  });
  return scans;
}

std::vector<ImuSample> ReadBagImu(const std::string& bag_path, const std::string& topic, bool record_time) {
  if (DetectBagFormat(bag_path) == BagFormat::kRos1) return ReadRos1BagImu(bag_path, topic, record_time);
  std::vector<ImuSample> samples;
  ForEachRos2Message(bag_path, topic, [&](const Ros2Message& m) {
    const std::string source = SourceOf(bag_path, m, samples.size());
    RequireType(m, source, "sensor_msgs", "Imu");
    ImuSample sample;
    const Ros2Header header = DecodeRos2Imu(m.data, m.size, source, sample);
    sample.stamp = record_time || header.stamp == 0.0 ? double(m.log_time) * 1e-9 : header.stamp;
    AppendBagImuSample(samples, sample, source);
  });
  return samples;
}

Trajectory ReadBagPoses(const std::string& bag_path, const std::string& topic, const std::string& child_frame) {
  if (DetectBagFormat(bag_path) == BagFormat::kRos1) {
    throw FileError(bag_path, "reference poses are read from ROS 2 bags (convert a ROS1 bag's with a TUM file)");
  }
  std::vector<StampedPose> poses;
  std::size_t index = 0;
  ForEachRos2Message(bag_path, topic, [&](const Ros2Message& m) {
    const std::string source = SourceOf(bag_path, m, index++);
    if (child_frame.empty() && IsRosType(*m.type, "tf2_msgs", "TFMessage")) {
      throw FileError(bag_path, "topic '" + Printable(topic) +
                                    "' holds transforms (tf2_msgs/TFMessage): name the child frame, BAG:" + topic +
                                    ":child_frame");
    }
    if (IsRosType(*m.type, "nav_msgs", "Path")) {
      std::vector<double> stamps;
      std::vector<SE3d> path;
      DecodeRos2Path(m.data, m.size, source, stamps, path);
      poses.clear();
      for (std::size_t k = 0; k < path.size(); ++k) poses.push_back({stamps[k], path[k]});
      return;
    }
    double stamp = 0.0;
    SE3d pose;
    if (!DecodeRos2Pose(*m.type, m.data, m.size, source, child_frame, stamp, pose)) return;
    if (stamp == 0.0) stamp = double(m.log_time) * 1e-9;
    if (!poses.empty() && !(stamp > poses.back().time)) {
      throw FileError(source, "stamp " + std::to_string(stamp) + " s is not after the previous pose's");
    }
    poses.push_back({stamp, pose});
  });
  if (poses.size() < 2) {
    throw FileError(bag_path, "topic '" + Printable(topic) + "' holds fewer than 2 poses" +
                                  (child_frame.empty() ? "" : " of child frame '" + Printable(child_frame) + "'"));
  }
  for (std::size_t k = 1; k < poses.size(); ++k) {
    if (!(poses[k].time > poses[k - 1].time)) throw FileError(bag_path, "the path's stamps do not increase");
  }
  return Trajectory(std::move(poses));
}

}  // namespace radargauss
