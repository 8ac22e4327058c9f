// SPDX-License-Identifier: BSD-3-Clause
// The ROS 2 messages radargauss reads and writes, in CDR (docs/design/formats.md,
// "ROS 2 bags"): a 4-byte encapsulation header, then the fields little- or
// big-endian, each aligned to its size (XCDR1) or to at most 4 bytes
// (XCDR2, plain). Strings and sequences are bounded by the message's bytes:
// a message that lies about a length gets one DataError naming `source`.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "radargauss/io/imu.hpp"
#include "radargauss/io/rosbag.hpp"
#include "radargauss/lie/se3.hpp"

namespace radargauss {

// A message's header: its stamp (s; 0 when the stamp is zero) and frame.
struct Ros2Header {
  double stamp = 0.0;
  std::string frame_id;
};

// sensor_msgs/msg/PointCloud2.
Ros2Header DecodeRos2PointCloud2(const std::uint8_t* data, std::size_t size, const std::string& source,
                                 PointCloud2Data& cloud);
// sensor_msgs/msg/Imu: its angular velocity and linear acceleration.
Ros2Header DecodeRos2Imu(const std::uint8_t* data, std::size_t size, const std::string& source, ImuSample& sample);
// A pose with its stamp, from geometry_msgs/msg/PoseStamped, nav_msgs/msg/Odometry
// or the transform of tf2_msgs/msg/TFMessage whose child frame is `child_frame`
// (false when the message has none).
bool DecodeRos2Pose(const std::string& type, const std::uint8_t* data, std::size_t size, const std::string& source,
                    const std::string& child_frame, double& stamp, SE3d& pose);

// nav_msgs/msg/Path: its poses with their stamps.
Ros2Header DecodeRos2Path(const std::uint8_t* data, std::size_t size, const std::string& source,
                          std::vector<double>& stamps, std::vector<SE3d>& poses);

// Whether `type` ("sensor_msgs/msg/PointCloud2", or the ROS1 spelling
// "sensor_msgs/PointCloud2") names `package`/`name`.
bool IsRosType(const std::string& type, const std::string& package, const std::string& name);

enum class CdrEncoding { kXcdr1LittleEndian, kXcdr1BigEndian, kXcdr2LittleEndian, kXcdr2BigEndian };

std::vector<std::uint8_t> EncodeRos2PointCloud2(const Ros2Header& header, const PointCloud2Data& cloud,
                                                CdrEncoding encoding = CdrEncoding::kXcdr1LittleEndian);
std::vector<std::uint8_t> EncodeRos2Imu(const Ros2Header& header, const ImuSample& sample,
                                        CdrEncoding encoding = CdrEncoding::kXcdr1LittleEndian);
std::vector<std::uint8_t> EncodeRos2PoseStamped(const Ros2Header& header, const SE3d& pose,
                                                CdrEncoding encoding = CdrEncoding::kXcdr1LittleEndian);

// nav_msgs/msg/Path: the poses with their stamps, all in the header's frame.
std::vector<std::uint8_t> EncodeRos2Path(const Ros2Header& header, const std::vector<double>& stamps,
                                         const std::vector<SE3d>& poses,
                                         CdrEncoding encoding = CdrEncoding::kXcdr1LittleEndian);
// tf2_msgs/msg/TFMessage of one transform: `child` in the header's frame.
std::vector<std::uint8_t> EncodeRos2Transform(const Ros2Header& header, const std::string& child, const SE3d& pose,
                                              CdrEncoding encoding = CdrEncoding::kXcdr1LittleEndian);
// One visualization_msgs/msg/Marker (the fields ROS 2 Humble has).
struct Ros2Marker {
  Ros2Header header;
  std::string ns;
  std::int32_t id = 0;
  std::int32_t type = 2;  // 2 SPHERE, 5 LINE_LIST
  SE3d pose;
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  Eigen::Vector4f color = Eigen::Vector4f(1, 1, 1, 1);  // r g b a
  std::vector<Eigen::Vector3d> points;
};
std::vector<std::uint8_t> EncodeRos2MarkerArray(const std::vector<Ros2Marker>& markers,
                                                CdrEncoding encoding = CdrEncoding::kXcdr1LittleEndian);

// The message definitions (ros2msg, dependencies appended as rosbag2 writes
// them) that an MCAP schema carries.
const std::string& Ros2MessageDefinition(const std::string& type);

// A stamp in s as ROS's (sec, nanosec), and back as ROS computes it.
void SplitStamp(double stamp, std::int32_t& sec, std::uint32_t& nanosec);
// Whether SplitStamp takes `stamp`: 0 to 2^31 s (1970 to 2038).
bool FitsRosTime(double stamp);
inline double JoinStamp(std::int32_t sec, std::uint32_t nanosec) { return double(sec) + 1e-9 * double(nanosec); }
// The stamp as ns since the epoch, through SplitStamp (a bag's log time).
std::int64_t StampNanoseconds(double stamp);

}  // namespace radargauss
