// SPDX-License-Identifier: BSD-3-Clause
// ROS 2 bags without ROS (docs/design.md, "ROS 2 bags"): a rosbag2 folder
// (its metadata.yaml and every file it lists, in order), or one of its
// files alone: sqlite3 (.db3, schema versions 1-4, through Debian's
// libsqlite3) or MCAP (io/mcap.hpp). Told apart by content, not by name.
// Messages are CDR (io/ros2_messages.hpp); per-message zstd compression
// (compression_mode MESSAGE) is undone, a whole-file one is refused.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "radargauss/io/mcap.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/core/trajectory.hpp"

namespace radargauss {

enum class BagFormat { kRos1, kSqlite3, kMcap, kRos2Folder };

// What `path` holds, by its first bytes (a folder: by its metadata.yaml).
// Throws DataError naming it when it is none of these.
BagFormat DetectBagFormat(const std::string& path);

// One message of a ROS 2 bag; `data` lives until the visitor returns.
struct Ros2Message {
  const std::string* topic = nullptr;
  const std::string* type = nullptr;  // "sensor_msgs/msg/PointCloud2"
  std::int64_t log_time = 0;          // ns: the recorder's receive time
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
};

// Calls visit for every message on `topic` (every topic when empty), file by
// file, in each file's time order (sqlite3) or file order (MCAP). Throws
// DataError naming the file for a malformed bag or a missing topic.
void ForEachRos2Message(const std::string& path, const std::string& topic,
                        const std::function<void(const Ros2Message&)>& visit);
std::vector<BagTopic> ListRos2Topics(const std::string& path);

// Reference poses from a ROS 2 bag's `topic`: geometry_msgs/msg/PoseStamped
// or nav_msgs/msg/Odometry (each message's pose at its stamp),
// tf2_msgs/msg/TFMessage (the transforms whose child frame is
// `child_frame`), or nav_msgs/msg/Path (the last message's poses). Stamps
// that do not increase are refused; DataError names the message.
Trajectory ReadBagPoses(const std::string& path, const std::string& topic, const std::string& child_frame = "");

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

// Empty when `name` is a topic name ROS accepts: '/' then parts of letters,
// digits and '_' that do not start with a digit, separated by single '/';
// otherwise why not.
std::string TopicNameFault(const std::string& name);
// Throws DataError for the first of (what names it, topic) whose topic has a
// TopicNameFault or was named before: "--scan-topic '' is empty".
void CheckBagTopics(const std::vector<std::pair<std::string, std::string>>& topics);

}  // namespace radargauss
