// SPDX-License-Identifier: BSD-3-Clause
// Writing ROS 2 bags (.mcap, .db3): Ros2BagWriter over one writer per format, and WriteRos2Bag.
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <tuple>

#include "radargauss/core/atomic_file.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/io/bag_writer.hpp"
#include "sqlite_database.hpp"

namespace radargauss {

namespace fs = std::filesystem;

namespace {

// One format's file, written at a temporary path that Ros2BagWriter renames.
class FormatWriter {
 public:
  virtual ~FormatWriter() = default;
  // The topic's id: 1, 2, ... in the order added.
  virtual void AddTopic(int id, const std::string& name, const std::string& type) = 0;
  virtual void Write(int topic, std::int64_t log_time, const std::vector<std::uint8_t>& data) = 0;
  virtual void Close() = 0;
};

class McapFile final : public FormatWriter {
 public:
  McapFile(const std::string& path, const std::string& temporary, const McapWriterOptions& options) : path_(path) {
    file_.open(temporary, std::ios::binary | std::ios::trunc);
    if (!file_) throw FileError(path, "cannot write");
    mcap_ = std::make_unique<McapWriter>(file_, options);
  }
  void AddTopic(int, const std::string& name, const std::string& type) override {
    const std::uint16_t schema = mcap_->AddSchema(type, "ros2msg", Ros2MessageDefinition(type));
    channels_.push_back(mcap_->AddChannel(name, schema, "cdr"));
  }
  void Write(int topic, std::int64_t log_time, const std::vector<std::uint8_t>& data) override {
    mcap_->Write(channels_[std::size_t(topic - 1)], std::uint64_t(log_time), std::uint64_t(log_time), data);
  }
  void Close() override {
    mcap_->Finish();
    file_.close();
    if (!file_) throw FileError(path_, "cannot write");
  }

 private:
  std::string path_;
  std::ofstream file_;
  std::unique_ptr<McapWriter> mcap_;
  std::vector<std::uint16_t> channels_;  // topic id - 1 -> channel
};

class SqliteFile final : public FormatWriter {
 public:
  explicit SqliteFile(const std::string& temporary)
      : db_(std::make_unique<Database>(temporary, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE)) {
    db_->Execute(
        "PRAGMA journal_mode=OFF; PRAGMA synchronous=OFF;"
        "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
        "INSERT INTO schema VALUES(3, 'humble');"
        "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
        " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
        "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL,"
        " data BLOB NOT NULL);"
        "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
        "BEGIN TRANSACTION;");
    insert_ =
        std::make_unique<Database::Statement>(*db_, "INSERT INTO messages(topic_id, timestamp, data) VALUES(?, ?, ?)");
  }
  ~SqliteFile() override {
    insert_.reset();
    db_.reset();
  }
  void AddTopic(int id, const std::string& name, const std::string& type) override {
    Ros2MessageDefinition(type);  // a type this writer knows
    Database::Statement topic(*db_, "INSERT INTO topics VALUES(?, ?, ?, 'cdr', '')");
    topic.Bind(1, std::int64_t(id));
    topic.Bind(2, name);
    topic.Bind(3, type);
    topic.Step();
  }
  void Write(int topic, std::int64_t log_time, const std::vector<std::uint8_t>& data) override {
    insert_->Reset();
    insert_->Bind(1, std::int64_t(topic));
    insert_->Bind(2, log_time);
    insert_->Bind(3, data);
    insert_->Step();
  }
  void Close() override {
    db_->Execute("COMMIT;");
    insert_.reset();
    db_.reset();
  }

 private:
  std::unique_ptr<Database> db_;
  std::unique_ptr<Database::Statement> insert_;
};

}  // namespace

struct Ros2BagWriter::Impl {
  std::string path, temporary;
  std::unique_ptr<FormatWriter> format;
  int topics = 0;
  bool finished = false;
};

Ros2BagWriter::Ros2BagWriter(const std::string& path, BagFormat format, const McapWriterOptions& mcap)
    : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  w.path = path;
  w.temporary = TemporaryFileFor(path);
  std::remove(w.temporary.c_str());
  switch (format) {
    case BagFormat::kMcap:
      w.format = std::make_unique<McapFile>(path, w.temporary, mcap);
      break;
    case BagFormat::kSqlite3:
      w.format = std::make_unique<SqliteFile>(w.temporary);
      break;
    default:
      throw std::invalid_argument("Ros2BagWriter writes .mcap or .db3 files");
  }
}

Ros2BagWriter::~Ros2BagWriter() {
  if (impl_->finished) return;
  impl_->format.reset();
  std::remove(impl_->temporary.c_str());
}

int Ros2BagWriter::AddTopic(const std::string& name, const std::string& type) {
  impl_->format->AddTopic(impl_->topics + 1, name, type);
  return ++impl_->topics;
}

void Ros2BagWriter::Write(int topic, std::int64_t log_time, const std::vector<std::uint8_t>& data) {
  if (topic < 1 || topic > impl_->topics) throw std::invalid_argument("Ros2BagWriter: no such topic");
  impl_->format->Write(topic, log_time, data);
}

void Ros2BagWriter::Finish() {
  Impl& w = *impl_;
  if (w.finished) return;
  w.format->Close();
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

void WriteRigBag(const std::string& path, BagFormat format, const std::vector<RigBagRadar>& radars,
                 const McapWriterOptions& mcap) {
  std::vector<std::pair<std::string, std::string>> topics;
  for (const RigBagRadar& radar : radars) topics.emplace_back("radar '" + radar.frame + "'s topic", radar.topic);
  CheckBagTopics(topics);
  // Every scan by its stamp, checked before the bag is begun.
  std::vector<std::tuple<double, std::size_t, std::size_t>> order;  // stamp, radar, scan
  for (std::size_t r = 0; r < radars.size(); ++r) {
    for (std::size_t k = 0; k < radars[r].scans->size(); ++k) {
      const double stamp = (*radars[r].scans)[k].timestamp;
      if (!FitsRosTime(stamp)) {
        throw DataError("radar '" + radars[r].frame + "', scan " + std::to_string(k) + ": stamp " +
                        std::to_string(stamp) + " s does not fit ROS's time (0 to 2^31 s since 1970)");
      }
      order.emplace_back(stamp, r, k);
    }
  }
  std::stable_sort(order.begin(), order.end());
  Ros2BagWriter writer(path, format, mcap);
  std::vector<int> ids;
  for (const RigBagRadar& radar : radars) ids.push_back(writer.AddTopic(radar.topic, "sensor_msgs/msg/PointCloud2"));
  for (const auto& [stamp, r, k] : order) {
    const RadarScan& scan = (*radars[r].scans)[k];
    writer.Write(ids[r], StampNanoseconds(stamp),
                 EncodeRos2PointCloud2({stamp, radars[r].frame}, EncodePointCloud2(scan)));
  }
  writer.Finish();
}

}  // namespace radargauss
