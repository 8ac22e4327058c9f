// SPDX-License-Identifier: BSD-3-Clause
// Writing ROS 2 bags without ROS (docs/design/formats.md, "ROS 2 bags"): an
// .mcap or a .db3 file, its messages in CDR (io/ros2_messages.hpp).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "radargauss/core/trajectory.hpp"
#include "radargauss/io/mcap.hpp"
#include "radargauss/io/rosbag.hpp"

namespace radargauss {

// Writes a ROS 2 bag file (an .mcap or a .db3, chosen by `format`)
// atomically: nothing appears at `path` until Finish succeeds.
class Ros2BagWriter {
 public:
  Ros2BagWriter(const std::string& path, BagFormat format, const McapWriterOptions& mcap = {});
  ~Ros2BagWriter();
  Ros2BagWriter(const Ros2BagWriter&) = delete;
  Ros2BagWriter& operator=(const Ros2BagWriter&) = delete;

  // A topic of `type` (its definition from Ros2MessageDefinition); returns its id.
  int AddTopic(const std::string& name, const std::string& type);
  void Write(int topic, std::int64_t log_time, const std::vector<std::uint8_t>& data);
  void Finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Scans as a ROS 2 bag (`radargauss convert`): each as
// sensor_msgs/msg/PointCloud2 (EncodePointCloud2), the IMU samples as
// sensor_msgs/msg/Imu and, with a reference, T_world_radar at each scan
// within its span as geometry_msgs/msg/PoseStamped; all in time order, each
// message logged at its own stamp.
struct BagExportOptions {
  std::string scan_topic = "/radar/points";
  std::string imu_topic = "/imu/data";
  std::string pose_topic = "/reference/pose";
  std::string radar_frame = "radar", imu_frame = "imu", world_frame = "world";
  McapWriterOptions mcap;
};
// Throws DataError before anything is written for a topic name a reader
// would not find again (TopicNameFault), two topics of one name, or a stamp
// outside ROS's time ("scan 3: stamp -5 s ...").
void WriteRos2Bag(const std::string& path, BagFormat format, const std::vector<RadarScan>& scans,
                  const std::vector<ImuSample>& imu, const Trajectory* reference, const BagExportOptions& options = {});

// A rig's radars as one ROS 2 bag (`radargauss convert --rig`): each
// radar's scans as sensor_msgs/msg/PointCloud2 on its topic, with its frame
// id, stamped on its own clock; all radars' messages in one order of their
// stamps (a tie: the radar listed first). Throws DataError, before anything
// is written, as WriteRos2Bag does.
struct RigBagRadar {
  std::string topic;
  std::string frame;
  const std::vector<RadarScan>* scans = nullptr;
};
void WriteRigBag(const std::string& path, BagFormat format, const std::vector<RigBagRadar>& radars,
                 const McapWriterOptions& mcap = {});

// Empty when `name` is a topic name ROS accepts: '/' then parts of letters,
// digits and '_' that do not start with a digit, separated by single '/';
// otherwise why not.
std::string TopicNameFault(const std::string& name);
// Throws DataError for the first of (what names it, topic) whose topic has a
// TopicNameFault or was named before: "--scan-topic '' is empty".
void CheckBagTopics(const std::vector<std::pair<std::string, std::string>>& topics);

}  // namespace radargauss
