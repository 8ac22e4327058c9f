// SPDX-License-Identifier: BSD-3-Clause
// Writing ROS 2 bags (.mcap, .db3): Ros2BagWriter and WriteRos2Bag.
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/io/rosbag2.hpp"
#include "sqlite_database.hpp"

namespace radargauss {

namespace fs = std::filesystem;

struct Ros2BagWriter::Impl {
  std::string path, temporary;
  BagFormat format;
  McapWriterOptions mcap_options;
  std::ofstream file;
  std::unique_ptr<McapWriter> mcap;
  std::unique_ptr<Database> db;
  std::unique_ptr<Database::Statement> insert;
  std::vector<std::uint16_t> channels;  // MCAP: topic id -> channel
  bool finished = false;
};

Ros2BagWriter::Ros2BagWriter(const std::string& path, BagFormat format, const McapWriterOptions& mcap)
    : impl_(std::make_unique<Impl>()) {
  if (format != BagFormat::kMcap && format != BagFormat::kSqlite3) {
    throw std::invalid_argument("Ros2BagWriter writes .mcap or .db3 files");
  }
  Impl& w = *impl_;
  w.path = path;
  w.temporary = TemporaryFileFor(path);
  w.format = format;
  w.mcap_options = mcap;
  std::remove(w.temporary.c_str());
  if (format == BagFormat::kMcap) {
    w.file.open(w.temporary, std::ios::binary | std::ios::trunc);
    if (!w.file) throw FileError(path, "cannot write");
    w.mcap = std::make_unique<McapWriter>(w.file, mcap);
    return;
  }
  w.db = std::make_unique<Database>(w.temporary, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  w.db->Execute(
      "PRAGMA journal_mode=OFF; PRAGMA synchronous=OFF;"
      "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
      "INSERT INTO schema VALUES(3, 'humble');"
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
      " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL,"
      " data BLOB NOT NULL);"
      "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
      "BEGIN TRANSACTION;");
  w.insert =
      std::make_unique<Database::Statement>(*w.db, "INSERT INTO messages(topic_id, timestamp, data) VALUES(?, ?, ?)");
}

Ros2BagWriter::~Ros2BagWriter() {
  if (impl_->finished) return;
  impl_->insert.reset();
  impl_->db.reset();
  impl_->file.close();
  std::remove(impl_->temporary.c_str());
}

int Ros2BagWriter::AddTopic(const std::string& name, const std::string& type) {
  Impl& w = *impl_;
  if (w.format == BagFormat::kMcap) {
    const std::uint16_t schema = w.mcap->AddSchema(type, "ros2msg", Ros2MessageDefinition(type));
    w.channels.push_back(w.mcap->AddChannel(name, schema, "cdr"));
    return int(w.channels.size());
  }
  Ros2MessageDefinition(type);  // a type this writer knows
  const int id = int(w.channels.size() + 1);
  w.channels.push_back(std::uint16_t(id));
  Database::Statement topic(*w.db, "INSERT INTO topics VALUES(?, ?, ?, 'cdr', '')");
  topic.Bind(1, std::int64_t(id));
  topic.Bind(2, name);
  topic.Bind(3, type);
  topic.Step();
  return id;
}

void Ros2BagWriter::Write(int topic, std::int64_t log_time, const std::vector<std::uint8_t>& data) {
  Impl& w = *impl_;
  if (topic < 1 || std::size_t(topic) > w.channels.size()) throw std::invalid_argument("Ros2BagWriter: no such topic");
  if (w.format == BagFormat::kMcap) {
    w.mcap->Write(w.channels[std::size_t(topic - 1)], std::uint64_t(log_time), std::uint64_t(log_time), data);
    return;
  }
  w.insert->Reset();
  w.insert->Bind(1, std::int64_t(topic));
  w.insert->Bind(2, log_time);
  w.insert->Bind(3, data);
  w.insert->Step();
}

void Ros2BagWriter::Finish() {
  Impl& w = *impl_;
  if (w.finished) return;
  if (w.format == BagFormat::kMcap) {
    w.mcap->Finish();
    w.file.close();
    if (!w.file) throw FileError(w.path, "cannot write");
  } else {
    w.db->Execute("COMMIT;");
    w.insert.reset();
    w.db.reset();
  }
  std::error_code error;
  fs::rename(w.temporary, w.path, error);
  if (error) throw FileError(w.path, "cannot write: " + error.message());
  w.finished = true;
}

std::string TopicNameFault(const std::string& name) {
  if (name.empty()) return "is empty";
  if (name[0] != '/') return "does not start with '/'";
  for (std::size_t i = 1; i <= name.size(); ++i) {
    const bool part_starts = name[i - 1] == '/';
    if (i == name.size()) return part_starts ? "ends in '/'" : "";
    const unsigned char c = static_cast<unsigned char>(name[i]);
    if (part_starts && (c == '/' || std::isdigit(c))) return "has a part that is empty or starts with a digit";
    if (c != '/' && c != '_' && !std::isalnum(c)) return "holds '" + Printable(std::string(1, char(c))) + "'";
  }
  return "";
}

void CheckBagTopics(const std::vector<std::pair<std::string, std::string>>& topics) {
  for (std::size_t i = 0; i < topics.size(); ++i) {
    const std::string fault = TopicNameFault(topics[i].second);
    if (!fault.empty()) throw DataError(topics[i].first + " '" + Printable(topics[i].second) + "' " + fault);
    for (std::size_t j = 0; j < i; ++j) {
      if (topics[i].second == topics[j].second) {
        throw DataError(topics[j].first + " and " + topics[i].first + " are both " + topics[i].second);
      }
    }
  }
}

void WriteRos2Bag(const std::string& path, BagFormat format, const std::vector<RadarScan>& scans,
                  const std::vector<ImuSample>& imu, const Trajectory* reference, const BagExportOptions& options) {
  // Everything checked before the bag is begun: a refused bag leaves no file.
  std::vector<std::pair<std::string, std::string>> topics = {{"scan topic", options.scan_topic}};
  if (!imu.empty()) topics.emplace_back("IMU topic", options.imu_topic);
  if (reference) topics.emplace_back("pose topic", options.pose_topic);
  CheckBagTopics(topics);
  const auto check_stamp = [](double stamp, const std::string& what) {
    if (!FitsRosTime(stamp)) {
      throw DataError(what + ": stamp " + std::to_string(stamp) +
                      " s does not fit ROS's time (0 to 2^31 s since 1970; seconds expected)");
    }
  };
  for (std::size_t k = 0; k < scans.size(); ++k) check_stamp(scans[k].timestamp, "scan " + std::to_string(k));
  for (std::size_t k = 0; k < imu.size(); ++k) check_stamp(imu[k].stamp, "IMU sample " + std::to_string(k));
  Ros2BagWriter writer(path, format, options.mcap);
  const int scan_topic = writer.AddTopic(options.scan_topic, "sensor_msgs/msg/PointCloud2");
  const int imu_topic = imu.empty() ? 0 : writer.AddTopic(options.imu_topic, "sensor_msgs/msg/Imu");
  const int pose_topic = reference ? writer.AddTopic(options.pose_topic, "geometry_msgs/msg/PoseStamped") : 0;
  // Merged by time: each scan (and its pose) after the IMU samples up to its stamp.
  std::size_t next_imu = 0;
  const auto write_imu_until = [&](double stamp) {
    for (; next_imu < imu.size() && imu[next_imu].stamp <= stamp; ++next_imu) {
      const ImuSample& sample = imu[next_imu];
      writer.Write(imu_topic, StampNanoseconds(sample.stamp), EncodeRos2Imu({sample.stamp, options.imu_frame}, sample));
    }
  };
  for (const RadarScan& scan : scans) {
    write_imu_until(scan.timestamp);
    const std::int64_t at = StampNanoseconds(scan.timestamp);
    writer.Write(scan_topic, at, EncodeRos2PointCloud2({scan.timestamp, options.radar_frame}, EncodePointCloud2(scan)));
    const std::optional<SE3d> pose = reference ? reference->Interpolate(scan.timestamp) : std::nullopt;
    if (pose) writer.Write(pose_topic, at, EncodeRos2PoseStamped({scan.timestamp, options.world_frame}, *pose));
  }
  write_imu_until(std::numeric_limits<double>::infinity());
  writer.Finish();
}

}  // namespace radargauss
