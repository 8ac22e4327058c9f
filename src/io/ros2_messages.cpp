// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/ros2_messages.hpp"

#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>

#include "radargauss/core/error.hpp"

namespace radargauss {

namespace {

// Reads one CDR message: the encapsulation header picks the byte order and
// the alignment rule; offsets align from the end of that header.
class CdrReader {
 public:
  CdrReader(const std::uint8_t* data, std::size_t size, const std::string& source)
      : data_(data), size_(size), source_(source) {
    if (size < 4) throw FileError(source, "a CDR message shorter than its 4-byte header");
    if (data[0] != 0) throw FileError(source, "not a CDR message (encapsulation " + Kind() + ")");
    switch (data[1]) {
      case 0x00:  // CDR_BE
        big_endian_ = true;
        break;
      case 0x01:  // CDR_LE
        break;
      case 0x10:  // CDR2_BE
        big_endian_ = true;
        max_alignment_ = 4;
        break;
      case 0x11:  // CDR2_LE
        max_alignment_ = 4;
        break;
      default:
        throw FileError(source, "CDR encapsulation " + Kind() + " is not plain XCDR1 or XCDR2");
    }
    data_ += 4;
    size_ -= 4;
  }

  template <typename T>
  T Read() {
    Align(sizeof(T));
    Need(sizeof(T));
    std::uint8_t bytes[sizeof(T)];
    for (std::size_t i = 0; i < sizeof(T); ++i) bytes[i] = data_[pos_ + (big_endian_ ? sizeof(T) - 1 - i : i)];
    pos_ += sizeof(T);
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  }
  double Stamp() {
    const auto sec = Read<std::int32_t>();
    const auto nanosec = Read<std::uint32_t>();
    if (nanosec >= 1000000000u) throw FileError(source_, "a stamp's nanoseconds are 1e9 or more");
    return JoinStamp(sec, nanosec);
  }
  std::string String() {
    const auto n = Read<std::uint32_t>();
    Need(n);
    std::string s(reinterpret_cast<const char*>(data_ + pos_), n);
    pos_ += n;
    if (!s.empty() && s.back() == '\0') s.pop_back();
    // A CDR string ends at its one NUL: one inside would cut every name and message short.
    if (s.find('\0') != std::string::npos) throw FileError(source_, "a string holds a NUL byte before its end");
    return s;
  }
  // A sequence's length, checked against the bytes left at `element_bytes` each.
  std::uint32_t Length(std::size_t element_bytes) {
    const auto n = Read<std::uint32_t>();
    if (std::uint64_t(n) * element_bytes > size_ - pos_) {
      throw FileError(source_, "a sequence of " + std::to_string(n) + " elements is longer than the message");
    }
    return n;
  }
  void Bytes(std::size_t n, std::vector<std::uint8_t>& out) {
    Need(n);
    out.assign(data_ + pos_, data_ + pos_ + n);
    pos_ += n;
  }
  Ros2Header Header() {
    Ros2Header header;
    header.stamp = Stamp();
    header.frame_id = String();
    return header;
  }
  Eigen::Vector3d Vector3() {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v(i) = Read<double>();
    return v;
  }
  SE3d Pose() {  // position, then orientation x y z w
    const Eigen::Vector3d t = Vector3();
    double q[4];
    for (double& c : q) c = Read<double>();
    if (!(std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]) && std::isfinite(q[3])) || !t.allFinite() ||
        std::abs(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] - 1.0) > 1e-3) {
      throw FileError(source_, "a pose that is not finite or whose quaternion is not unit");
    }
    return SE3d(SO3d::FromXyzw(q), t);
  }
  void Skip(std::size_t doubles) {
    for (std::size_t i = 0; i < doubles; ++i) Read<double>();
  }

 private:
  std::string Kind() const {
    static const char kHex[] = "0123456789abcdef";
    return std::string("0x") + kHex[data_[0] >> 4] + kHex[data_[0] & 15] + kHex[data_[1] >> 4] + kHex[data_[1] & 15];
  }
  void Align(std::size_t n) {
    const std::size_t a = std::min(n, max_alignment_);
    pos_ = std::min(size_, (pos_ + a - 1) / a * a);
  }
  void Need(std::uint64_t n) const {
    if (n > size_ - pos_) throw FileError(source_, "CDR message is shorter than its fields");
  }
  const std::uint8_t* data_;
  std::size_t size_, pos_ = 0;
  const std::string& source_;
  bool big_endian_ = false;
  std::size_t max_alignment_ = 8;
};

class CdrWriter {
 public:
  explicit CdrWriter(CdrEncoding encoding)
      : big_endian_(encoding == CdrEncoding::kXcdr1BigEndian || encoding == CdrEncoding::kXcdr2BigEndian),
        max_alignment_(encoding == CdrEncoding::kXcdr2LittleEndian || encoding == CdrEncoding::kXcdr2BigEndian ? 4
                                                                                                               : 8) {
    const std::uint8_t kind = std::uint8_t((max_alignment_ == 4 ? 0x10 : 0x00) | (big_endian_ ? 0x00 : 0x01));
    bytes_ = {0x00, kind, 0x00, 0x00};
  }
  template <typename T>
  void Write(T value) {
    const std::size_t a = std::min(sizeof(T), max_alignment_);
    while ((bytes_.size() - 4) % a != 0) bytes_.push_back(0);
    std::uint8_t raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    for (std::size_t i = 0; i < sizeof(T); ++i) bytes_.push_back(raw[big_endian_ ? sizeof(T) - 1 - i : i]);
  }
  void String(const std::string& s) {
    Write(std::uint32_t(s.size() + 1));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back(0);
  }
  void Header(const Ros2Header& header) {
    std::int32_t sec;
    std::uint32_t nanosec;
    SplitStamp(header.stamp, sec, nanosec);
    Write(sec);
    Write(nanosec);
    String(header.frame_id);
  }
  void Vector3(const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) Write(v(i));
  }
  void Covariance(int n) {
    for (int i = 0; i < n; ++i) Write(0.0);
  }
  std::vector<std::uint8_t>& bytes() { return bytes_; }

 private:
  bool big_endian_;
  std::size_t max_alignment_;
  std::vector<std::uint8_t> bytes_;
};

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
