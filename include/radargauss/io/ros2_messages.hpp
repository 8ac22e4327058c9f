// SPDX-License-Identifier: BSD-3-Clause
// The ROS 2 messages radargauss reads and writes, in CDR (docs/design.md,
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

// The message definitions (ros2msg, dependencies appended as rosbag2 writes
// them) that an MCAP schema carries.
const std::string& Ros2MessageDefinition(const std::string& type);

// A stamp in s as ROS's (sec, nanosec), and back as ROS computes it.
void SplitStamp(double stamp, std::int32_t& sec, std::uint32_t& nanosec);
inline double JoinStamp(std::int32_t sec, std::uint32_t nanosec) { return double(sec) + 1e-9 * double(nanosec); }

}  // namespace radargauss
