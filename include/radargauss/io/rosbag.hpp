// SPDX-License-Identifier: BSD-3-Clause
// Bags: what radargauss reads from them, whatever their format. ROS1 bags
// are read through Debian's ROS1 bag library (uncompressed, bz2 and lz4
// bags), ROS 2 bags (a rosbag2 folder, a .db3 or an .mcap file) without ROS;
// each format has its reader behind io/bag_reader.hpp, told apart by
// content. ROS1 support is an optional component: without it
// (RosbagSupported() false) a ROS1 bag gets a DataError saying so.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/io/imu.hpp"
#include "radargauss/io/field_mapping.hpp"
#include "radargauss/core/trajectory.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

bool RosbagSupported();

enum class BagFormat { kRos1, kSqlite3, kMcap, kRos2Folder };

// What `path` holds, by its first bytes (a folder: by its metadata.yaml).
// Throws DataError naming it when it is none of these.
BagFormat DetectBagFormat(const std::string& path);

struct BagTopic {
  std::string name;
  std::string type;
  std::size_t messages = 0;
  double first = 0.0, last = 0.0;  // s: the first and last message's record time
};

// Every topic of a bag of any kind, with its type, count and time span.
std::vector<BagTopic> ListBagTopics(const std::string& bag_path);

// One PointCloud2 message, as the bag holds it (for decoding and tests).
struct PointCloud2Field {
  std::string name;
  std::uint32_t offset = 0;
  std::uint8_t datatype = 7;  // sensor_msgs/PointField: 1 INT8 .. 7 FLOAT32, 8 FLOAT64
  std::uint32_t count = 1;
};
struct PointCloud2Data {
  std::uint32_t height = 1;
  std::uint32_t width = 0;
  std::vector<PointCloud2Field> fields;
  bool is_bigendian = false;
  std::uint32_t point_step = 0;
  std::uint32_t row_step = 0;
  std::vector<std::uint8_t> data;
};

// Decodes x y z and the mapped RCS / Doppler fields by name and datatype,
// honouring is_bigendian, point_step and row_step. Throws DataError naming
// `source` for inconsistent sizes, unknown datatypes or non-finite points.
RadarScan DecodePointCloud2(const PointCloud2Data& cloud, double timestamp, const FieldMapping& mapping,
                            const std::string& source);

// A scan as a PointCloud2 of one row: x y z, and doppler and rcs when the
// scan has them, as FLOAT64 (every value goes back exactly); little-endian.
PointCloud2Data EncodePointCloud2(const RadarScan& scan);

// Every PointCloud2 message of `topic`, in bag order (a ROS1 bag's time
// order; a ROS 2 file's: sqlite3 by time, MCAP as written). The scan time is
// the message header stamp, or the bag record time when the stamp is zero
// (the ti_mmwave driver leaves it zero).
std::vector<RadarScan> ReadBagScans(const std::string& bag_path, const std::string& topic,
                                    const FieldMapping& mapping = {});
// The same scans one at a time, each with its source (`BAG:TOPIC#index`);
// `visit` may move the scan away, and returns false to read no more.
void ForEachBagScan(const std::string& bag_path, const std::string& topic, const FieldMapping& mapping,
                    const std::function<bool(RadarScan&, const std::string&)>& visit);

// Every sensor_msgs/Imu message of `topic` (its angular velocity and linear
// acceleration as ImuSample's), in bag order, stamped by the
// header or, with `record_time`, by the bag's record time (the clock of
// scans whose header stamp is zero); throws DataError for a missing topic,
// another message type, non-finite values or stamps that do not increase.
std::vector<ImuSample> ReadBagImu(const std::string& bag_path, const std::string& topic, bool record_time = false);

// Appends a bag's IMU sample to `samples` after checking it: finite rates
// and force, a stamp after the last one's; DataError naming `source` otherwise.
void AppendBagImuSample(std::vector<ImuSample>& samples, const ImuSample& sample, const std::string& source);

// Reference poses from a ROS 2 bag's `topic`: geometry_msgs/msg/PoseStamped
// or nav_msgs/msg/Odometry (each message's pose at its stamp),
// tf2_msgs/msg/TFMessage (the transforms whose child frame is
// `child_frame`), or nav_msgs/msg/Path (the last message's poses). Stamps
// that do not increase are refused; DataError names the message.
Trajectory ReadBagPoses(const std::string& path, const std::string& topic, const std::string& child_frame = "");

}  // namespace radargauss
