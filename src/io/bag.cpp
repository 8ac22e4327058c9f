// SPDX-License-Identifier: BSD-3-Clause
// Bags of every kind behind one reader (io/bag_reader.hpp), and what is read
// from them (io/rosbag.hpp): scans, IMU samples and reference poses, each
// decoded by its message's codec.
#include <cstring>
#include <filesystem>
#include <fstream>

#include "bag_readers.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"
#include "radargauss/io/bag_reader.hpp"
#include "radargauss/io/mcap.hpp"
#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/io/rosbag.hpp"

namespace radargauss {

namespace {

std::string SourceOf(const std::string& bag, const BagMessage& m, std::size_t index) {
  return bag + ":" + *m.topic + "#" + std::to_string(index);
}

// Every message of `topic` in `bag_path`; DataError when there is none.
void ReadTopic(const std::string& bag_path, const std::string& topic,
               const std::function<void(const BagMessage&)>& visit) {
  std::size_t seen = 0;
  OpenBag(bag_path)->Read({{topic}}, [&](const BagMessage& m) {
    ++seen;
    visit(m);
  });
  if (seen == 0) throw FileError(bag_path, "no messages on topic '" + Printable(topic) + "'");
}

void RequireType(const BagMessage& m, const std::string& source, const char* package, const char* name) {
  if (!IsRosType(*m.type, package, name)) {
    // The type as the bag spells its types: ROS1's "sensor_msgs/Imu", ROS 2's "sensor_msgs/msg/Imu".
    const bool ros2 = m.type->find("/msg/") != std::string::npos;
    throw FileError(source, "message is " + Printable(*m.type) + ", not " + package + (ros2 ? "/msg/" : "/") + name);
  }
}

// ROS 2's CDR messages (io/ros2_messages.hpp).
class Cdr final : public MessageCodec {
 public:
  double RecordStamp(std::int64_t log_time) const override { return double(log_time) * 1e-9; }
  double PointCloud2(const BagMessage& m, const std::string& source, PointCloud2Data& cloud) const override {
    return DecodeRos2PointCloud2(m.data, m.size, source, cloud).stamp;
  }
  double Imu(const BagMessage& m, const std::string& source, ImuSample& sample) const override {
    return DecodeRos2Imu(m.data, m.size, source, sample).stamp;
  }
  bool Pose(const BagMessage& m, const std::string& source, const std::string& child_frame, double& stamp,
            SE3d& pose) const override {
    return DecodeRos2Pose(*m.type, m.data, m.size, source, child_frame, stamp, pose);
  }
  bool Path(const BagMessage& m, const std::string& source, std::vector<StampedPose>& path) const override {
    if (!IsRosType(*m.type, "nav_msgs", "Path")) return false;
    std::vector<double> stamps;
    std::vector<SE3d> poses;
    DecodeRos2Path(m.data, m.size, source, stamps, poses);
    path.clear();
    for (std::size_t k = 0; k < poses.size(); ++k) path.push_back({stamps[k], poses[k]});
    return true;
  }
};

}  // namespace

const MessageCodec& CdrCodec() {
  static const Cdr codec;
  return codec;
}

BagFormat DetectBagFormat(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    if (std::filesystem::exists(std::filesystem::path(path) / "metadata.yaml", error)) return BagFormat::kRos2Folder;
    throw FileError(path, "a folder without metadata.yaml is not a rosbag2 bag");
  }
  CheckRegularInputFile(path, "bag");
  std::ifstream file(path, std::ios::binary);
  char head[16] = {};
  file.read(head, sizeof(head));
  const std::size_t got = std::size_t(file.gcount());
  if (got >= 13 && std::memcmp(head, "#ROSBAG V2.0\n", 13) == 0) return BagFormat::kRos1;
  if (got >= 16 && std::memcmp(head, "SQLite format 3\0", 16) == 0) return BagFormat::kSqlite3;
  if (got >= 8 && IsMcapFile(path)) return BagFormat::kMcap;
  throw FileError(path, "not a bag: neither a ROS1 bag, a sqlite3 file, an MCAP file nor a rosbag2 folder");
}

std::unique_ptr<BagReader> OpenBag(const std::string& path) {
  switch (DetectBagFormat(path)) {
    case BagFormat::kRos1:
      return OpenRos1Bag(path);
    case BagFormat::kSqlite3:
      return OpenSqliteBag(path);
    case BagFormat::kMcap:
      return OpenMcapBag(path);
    case BagFormat::kRos2Folder:
      return OpenRos2Folder(path);
  }
  throw FileError(path, "not a bag");
}

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

std::vector<BagTopic> ListBagTopics(const std::string& bag_path) { return OpenBag(bag_path)->Topics(); }

void ForEachBagScan(const std::string& bag_path, const std::string& topic, const FieldMapping& mapping,
                    const std::function<bool(RadarScan&, const std::string&)>& visit) {
  PointCloud2Data cloud;
  std::size_t index = 0;
  bool reading = true;
  ReadTopic(bag_path, topic, [&](const BagMessage& m) {
    if (!reading) return;  // the reader has no stop: the rest pass undecoded
    const std::string source = SourceOf(bag_path, m, index++);
    RequireType(m, source, "sensor_msgs", "PointCloud2");
    const double header = m.codec->PointCloud2(m, source, cloud);
    const double stamp = header != 0.0 ? header : m.codec->RecordStamp(m.log_time);
    RadarScan scan = DecodePointCloud2(cloud, stamp, mapping, source);
    reading = visit(scan, source);
  });
}

std::vector<RadarScan> ReadBagScans(const std::string& bag_path, const std::string& topic,
                                    const FieldMapping& mapping) {
  std::vector<RadarScan> scans;
  ForEachBagScan(bag_path, topic, mapping, [&](RadarScan& scan, const std::string&) {
    scans.push_back(std::move(scan));
    return true;
  });
  return scans;
}

std::vector<ImuSample> ReadBagImu(const std::string& bag_path, const std::string& topic, bool record_time) {
  std::vector<ImuSample> samples;
  ReadTopic(bag_path, topic, [&](const BagMessage& m) {
    const std::string source = SourceOf(bag_path, m, samples.size());
    RequireType(m, source, "sensor_msgs", "Imu");
    ImuSample sample;
    const double header = m.codec->Imu(m, source, sample);
    sample.stamp = record_time || header == 0.0 ? m.codec->RecordStamp(m.log_time) : header;
    AppendBagImuSample(samples, sample, source);
  });
  return samples;
}

Trajectory ReadBagPoses(const std::string& bag_path, const std::string& topic, const std::string& child_frame) {
  std::vector<StampedPose> poses;
  std::size_t index = 0;
  ReadTopic(bag_path, topic, [&](const BagMessage& m) {
    const std::string source = SourceOf(bag_path, m, index++);
    if (child_frame.empty() && IsRosType(*m.type, "tf2_msgs", "TFMessage")) {
      throw FileError(bag_path, "topic '" + Printable(topic) +
                                    "' holds transforms (tf2_msgs/TFMessage): name the child frame, BAG:" + topic +
                                    ":child_frame");
    }
    if (m.codec->Path(m, source, poses)) return;
    double stamp = 0.0;
    SE3d pose;
    if (!m.codec->Pose(m, source, child_frame, stamp, pose)) return;
    if (stamp == 0.0) stamp = m.codec->RecordStamp(m.log_time);
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
