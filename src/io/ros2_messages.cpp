// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/ros2_messages.hpp"

#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>

#include "radargauss/core/error.hpp"
#include "cdr.hpp"

namespace radargauss {

namespace {

const char kRule[] = "================================================================================\n";
const std::string kHeaderDefinition = std::string(kRule) +
                                      "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n" + kRule +
                                      "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";
const std::string kQuaternionDefinition =
    std::string(kRule) + "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n";
const std::string kVector3Definition =
    std::string(kRule) + "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n";
const std::string kPointDefinition = std::string(kRule) + "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n";
const std::string kPoseDefinition = std::string(kRule) +
                                    "MSG: geometry_msgs/Pose\nPoint position\nQuaternion orientation\n" +
                                    kPointDefinition + kQuaternionDefinition;

}  // namespace

bool FitsRosTime(double stamp) { return std::isfinite(stamp) && stamp >= 0.0 && stamp < 2147483648.0; }

void SplitStamp(double stamp, std::int32_t& sec, std::uint32_t& nanosec) {
  if (!FitsRosTime(stamp)) {
    throw DataError("stamp " + std::to_string(stamp) + " s does not fit ROS's time");
  }
  const double whole = std::floor(stamp);
  auto ns = std::int64_t(std::llround((stamp - whole) * 1e9));
  auto s = std::int64_t(whole);
  if (ns >= 1000000000) {
    ns -= 1000000000;
    ++s;
  }
  sec = std::int32_t(s);
  nanosec = std::uint32_t(ns);
}

std::int64_t StampNanoseconds(double stamp) {
  std::int32_t sec;
  std::uint32_t nanosec;
  SplitStamp(stamp, sec, nanosec);
  return std::int64_t(sec) * 1000000000 + nanosec;
}

bool IsRosType(const std::string& type, const std::string& package, const std::string& name) {
  return type == package + "/msg/" + name || type == package + "/" + name;
}

Ros2Header DecodeRos2PointCloud2(const std::uint8_t* data, std::size_t size, const std::string& source,
                                 PointCloud2Data& cloud) {
  CdrReader cdr(data, size, source);
  const Ros2Header header = cdr.Header();
  cloud.height = cdr.Read<std::uint32_t>();
  cloud.width = cdr.Read<std::uint32_t>();
  const std::uint32_t fields = cdr.Length(13);  // a field takes 13 bytes at least
  cloud.fields.clear();
  for (std::uint32_t i = 0; i < fields; ++i) {
    PointCloud2Field field;
    field.name = cdr.String();
    field.offset = cdr.Read<std::uint32_t>();
    field.datatype = cdr.Read<std::uint8_t>();
    field.count = cdr.Read<std::uint32_t>();
    cloud.fields.push_back(field);
  }
  cloud.is_bigendian = cdr.Read<std::uint8_t>() != 0;
  cloud.point_step = cdr.Read<std::uint32_t>();
  cloud.row_step = cdr.Read<std::uint32_t>();
  cdr.Bytes(cdr.Length(1), cloud.data);
  return header;
}

Ros2Header DecodeRos2Imu(const std::uint8_t* data, std::size_t size, const std::string& source, ImuSample& sample) {
  CdrReader cdr(data, size, source);
  const Ros2Header header = cdr.Header();
  cdr.Skip(4 + 9);  // orientation and its covariance
  sample.angular_velocity = cdr.Vector3();
  cdr.Skip(9);
  sample.specific_force = cdr.Vector3();
  cdr.Skip(9);
  sample.stamp = header.stamp;
  return header;
}

bool DecodeRos2Pose(const std::string& type, const std::uint8_t* data, std::size_t size, const std::string& source,
                    const std::string& child_frame, double& stamp, SE3d& pose) {
  CdrReader cdr(data, size, source);
  if (IsRosType(type, "geometry_msgs", "PoseStamped")) {
    stamp = cdr.Header().stamp;
    pose = cdr.Pose();
    return true;
  }
  if (IsRosType(type, "nav_msgs", "Odometry")) {
    stamp = cdr.Header().stamp;
    cdr.String();  // child_frame_id
    pose = cdr.Pose();
    return true;
  }
  if (IsRosType(type, "tf2_msgs", "TFMessage")) {
    const std::uint32_t n = cdr.Length(8 + 4 + 4 + 7 * 8);
    for (std::uint32_t i = 0; i < n; ++i) {
      const double at = cdr.Header().stamp;
      const std::string child = cdr.String();
      const SE3d transform = cdr.Pose();
      if (child == child_frame) {
        stamp = at;
        pose = transform;
        return true;
      }
    }
    return false;
  }
  throw FileError(source, "message is " + Printable(type) +
                              ", not geometry_msgs/msg/PoseStamped, nav_msgs/msg/Odometry or tf2_msgs/msg/TFMessage");
}

Ros2Header DecodeRos2Path(const std::uint8_t* data, std::size_t size, const std::string& source,
                          std::vector<double>& stamps, std::vector<SE3d>& poses) {
  CdrReader cdr(data, size, source);
  const Ros2Header header = cdr.Header();
  const std::uint32_t n = cdr.Length(8 + 4 + 7 * 8);
  stamps.clear();
  poses.clear();
  for (std::uint32_t i = 0; i < n; ++i) {
    stamps.push_back(cdr.Header().stamp);
    poses.push_back(cdr.Pose());
  }
  return header;
}

std::vector<std::uint8_t> EncodeRos2PointCloud2(const Ros2Header& header, const PointCloud2Data& cloud,
                                                CdrEncoding encoding) {
  CdrWriter cdr(encoding);
  cdr.Header(header);
  cdr.Write(cloud.height);
  cdr.Write(cloud.width);
  cdr.Write(std::uint32_t(cloud.fields.size()));
  for (const PointCloud2Field& field : cloud.fields) {
    cdr.String(field.name);
    cdr.Write(field.offset);
    cdr.Write(field.datatype);
    cdr.Write(field.count);
  }
  cdr.Write(std::uint8_t(cloud.is_bigendian));
  cdr.Write(cloud.point_step);
  cdr.Write(cloud.row_step);
  cdr.Write(std::uint32_t(cloud.data.size()));
  cdr.bytes().insert(cdr.bytes().end(), cloud.data.begin(), cloud.data.end());
  cdr.Write(std::uint8_t(1));  // is_dense
  return std::move(cdr.bytes());
}

std::vector<std::uint8_t> EncodeRos2Imu(const Ros2Header& header, const ImuSample& sample, CdrEncoding encoding) {
  CdrWriter cdr(encoding);
  cdr.Header(header);
  for (const double c : {0.0, 0.0, 0.0, 1.0}) cdr.Write(c);
  cdr.Write(-1.0);  // orientation_covariance[0] = -1: no orientation
  cdr.Covariance(8);
  cdr.Vector3(sample.angular_velocity);
  cdr.Covariance(9);
  cdr.Vector3(sample.specific_force);
  cdr.Covariance(9);
  return std::move(cdr.bytes());
}

std::vector<std::uint8_t> EncodeRos2PoseStamped(const Ros2Header& header, const SE3d& pose, CdrEncoding encoding) {
  CdrWriter cdr(encoding);
  cdr.Header(header);
  const Eigen::Quaterniond& q = pose.rotation().quaternion();
  cdr.Vector3(pose.translation());
  for (const double c : {q.x(), q.y(), q.z(), q.w()}) cdr.Write(c);
  return std::move(cdr.bytes());
}

namespace {

void WritePose(CdrWriter& cdr, const SE3d& pose) {
  cdr.Vector3(pose.translation());
  const Eigen::Quaterniond& q = pose.rotation().quaternion();
  for (const double c : {q.x(), q.y(), q.z(), q.w()}) cdr.Write(c);
}

}  // namespace

std::vector<std::uint8_t> EncodeRos2Path(const Ros2Header& header, const std::vector<double>& stamps,
                                         const std::vector<SE3d>& poses, CdrEncoding encoding) {
  if (stamps.size() != poses.size()) throw std::invalid_argument("EncodeRos2Path: stamps and poses differ in count");
  CdrWriter cdr(encoding);
  cdr.Header(header);
  cdr.Write(std::uint32_t(poses.size()));
  for (std::size_t k = 0; k < poses.size(); ++k) {
    cdr.Header({stamps[k], header.frame_id});
    WritePose(cdr, poses[k]);
  }
  return std::move(cdr.bytes());
}

std::vector<std::uint8_t> EncodeRos2Transform(const Ros2Header& header, const std::string& child, const SE3d& pose,
                                              CdrEncoding encoding) {
  CdrWriter cdr(encoding);
  cdr.Write(std::uint32_t(1));
  cdr.Header(header);
  cdr.String(child);
  WritePose(cdr, pose);  // Transform: translation, rotation
  return std::move(cdr.bytes());
}

std::vector<std::uint8_t> EncodeRos2MarkerArray(const std::vector<Ros2Marker>& markers, CdrEncoding encoding) {
  CdrWriter cdr(encoding);
  cdr.Write(std::uint32_t(markers.size()));
  for (const Ros2Marker& m : markers) {
    cdr.Header(m.header);
    cdr.String(m.ns);
    cdr.Write(m.id);
    cdr.Write(m.type);
    cdr.Write(std::int32_t(0));  // ADD
    WritePose(cdr, m.pose);
    cdr.Vector3(m.scale);
    for (int i = 0; i < 4; ++i) cdr.Write(m.color(i));
    cdr.Write(std::int32_t(0));  // lifetime: forever
    cdr.Write(std::uint32_t(0));
    cdr.Write(std::uint8_t(0));  // frame_locked
    cdr.Write(std::uint32_t(m.points.size()));
    for (const Eigen::Vector3d& p : m.points) cdr.Vector3(p);
    cdr.Write(std::uint32_t(0));  // colors
    cdr.String("");               // text
    cdr.String("");               // mesh_resource
    cdr.Write(std::uint8_t(0));   // mesh_use_embedded_materials
  }
  return std::move(cdr.bytes());
}

const std::string& Ros2MessageDefinition(const std::string& type) {
  static const std::map<std::string, std::string> definitions = {
      {"sensor_msgs/msg/PointCloud2",
       "std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\nbool is_bigendian\n"
       "uint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n" +
           kHeaderDefinition + kRule +
           "MSG: sensor_msgs/PointField\nuint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\n"
           "uint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\n"
           "uint8 datatype\nuint32 count\n"},
      {"sensor_msgs/msg/Imu",
       "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n"
       "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n"
       "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n" +
           kHeaderDefinition + kQuaternionDefinition + kVector3Definition},
      {"geometry_msgs/msg/PoseStamped", "std_msgs/Header header\nPose pose\n" + kHeaderDefinition + kPoseDefinition},
      {"nav_msgs/msg/Path", "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n" + kHeaderDefinition + kRule +
                                "MSG: geometry_msgs/PoseStamped\nstd_msgs/Header header\nPose pose\n" +
                                kPoseDefinition},
      {"tf2_msgs/msg/TFMessage",
       "geometry_msgs/TransformStamped[] transforms\n" + std::string(kRule) +
           "MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\nTransform transform\n" +
           kHeaderDefinition + kRule + "MSG: geometry_msgs/Transform\nVector3 translation\nQuaternion rotation\n" +
           kVector3Definition + kQuaternionDefinition},
      {"visualization_msgs/msg/MarkerArray",
       "Marker[] markers\n" + std::string(kRule) +
           "MSG: visualization_msgs/Marker\nstd_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n"
           "geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n"
           "builtin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n"
           "std_msgs/ColorRGBA[] colors\nstring text\nstring mesh_resource\nbool mesh_use_embedded_materials\n" +
           kHeaderDefinition + kPoseDefinition + kVector3Definition + kRule +
           "MSG: std_msgs/ColorRGBA\nfloat32 r\nfloat32 g\nfloat32 b\nfloat32 a\n" + kRule +
           "MSG: builtin_interfaces/Duration\nint32 sec\nuint32 nanosec\n"},
  };
  const auto found = definitions.find(type);
  if (found == definitions.end()) throw DataError("no message definition for " + type);
  return found->second;
}

}  // namespace radargauss
