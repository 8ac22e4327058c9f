// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/rosbag2.hpp"

#include <sqlite3.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cctype>
#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>

#include "decompress.hpp"
#include "radargauss/atomic_file.hpp"
#include "radargauss/error.hpp"
#include "radargauss/io/read_file.hpp"
#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/io/yaml_file.hpp"

namespace radargauss {

namespace {

namespace fs = std::filesystem;

// One sqlite3 database, read-only, and its statements; every failure
// becomes a DataError naming the file.
class Database {
 public:
  Database(const std::string& path, int flags) : path_(path) {
    if (sqlite3_open_v2(path.c_str(), &db_, flags, nullptr) != SQLITE_OK) Fail("cannot open sqlite3 file");
  }
  ~Database() { sqlite3_close(db_); }
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  class Statement {
   public:
    Statement(Database& db, const std::string& sql) : db_(db) {
      if (sqlite3_prepare_v2(db.db_, sql.c_str(), -1, &statement_, nullptr) != SQLITE_OK) db.Fail("sqlite3");
    }
    ~Statement() { sqlite3_finalize(statement_); }
    Statement(const Statement&) = delete;
    Statement& operator=(const Statement&) = delete;
    bool Step() {
      const int status = sqlite3_step(statement_);
      if (status == SQLITE_ROW) return true;
      if (status != SQLITE_DONE) db_.Fail("sqlite3");
      return false;
    }
    void Bind(int index, std::int64_t value) { sqlite3_bind_int64(statement_, index, value); }
    void Bind(int index, const std::string& text) {
      sqlite3_bind_text(statement_, index, text.data(), int(text.size()), SQLITE_TRANSIENT);
    }
    void Bind(int index, const std::vector<std::uint8_t>& blob) {
      sqlite3_bind_blob64(statement_, index, blob.data(), blob.size(), SQLITE_STATIC);
    }
    void Reset() {
      sqlite3_reset(statement_);
      sqlite3_clear_bindings(statement_);
    }
    std::int64_t Int(int column) const { return sqlite3_column_int64(statement_, column); }
    std::string Text(int column) const {
      const unsigned char* text = sqlite3_column_text(statement_, column);
      return text ? std::string(reinterpret_cast<const char*>(text),
                                std::size_t(sqlite3_column_bytes(statement_, column)))
                  : std::string();
    }
    const std::uint8_t* Blob(int column, std::size_t& size) const {
      const void* blob = sqlite3_column_blob(statement_, column);
      size = std::size_t(sqlite3_column_bytes(statement_, column));
      return static_cast<const std::uint8_t*>(blob);
    }

   private:
    Database& db_;
    sqlite3_stmt* statement_ = nullptr;
  };

  void Execute(const std::string& sql) {
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) Fail("sqlite3");
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw FileError(path_, what + ": " + (db_ ? sqlite3_errmsg(db_) : "out of memory"));
  }
  bool HasTable(const std::string& name) {
    Statement query(*this, "SELECT count(*) FROM sqlite_master WHERE type='table' AND name='" + name + "'");
    return query.Step() && query.Int(0) > 0;
  }

 private:
  std::string path_;
  sqlite3* db_ = nullptr;
};

struct SqliteTopic {
  std::int64_t id = 0;
  std::string name, type, format;
};

std::vector<SqliteTopic> SqliteTopics(Database& db, const std::string& path) {
  if (!db.HasTable("topics") || !db.HasTable("messages")) {
    throw FileError(path, "not a rosbag2 sqlite3 file (no topics and messages tables)");
  }
  std::vector<SqliteTopic> topics;
  Database::Statement query(db, "SELECT id, name, type, serialization_format FROM topics ORDER BY id");
  while (query.Step()) topics.push_back({query.Int(0), query.Text(1), query.Text(2), query.Text(3)});
  return topics;
}

// Per-message zstd compression (rosbag2's compression_mode MESSAGE), undone
// into `out` with the same bound as an MCAP chunk; a frame may leave its
// size out (streamed up to the bound).
void DecompressMessage(const std::uint8_t* data, std::size_t size, const std::string& source,
                       std::vector<std::uint8_t>& out) {
  const unsigned long long content = ZSTD_getFrameContentSize(data, size);
  if (content == ZSTD_CONTENTSIZE_ERROR) throw FileError(source, "a message is not a zstd frame");
  const std::optional<std::uint64_t> stated =
      content == ZSTD_CONTENTSIZE_UNKNOWN ? std::nullopt : std::optional<std::uint64_t>(content);
  out = DecompressFrame(Codec::kZstd, data, size, stated, kMaxMcapChunkBytes, source, "a zstd message");
}

struct FolderPlan {
  std::vector<std::string> files;
  bool message_compression = false;
};

// metadata.yaml's files, in order, and whether its messages are compressed one by one.
FolderPlan ReadFolder(const std::string& folder) {
  const std::string metadata = (fs::path(folder) / "metadata.yaml").string();
  const YAML::Node root = ReadYamlDocument(metadata, "rosbag2 metadata");
  const YAML::Node info = root["rosbag2_bagfile_information"];
  if (!info || !info.IsMap()) throw FileError(metadata, "no rosbag2_bagfile_information");
  FolderPlan plan;
  const std::string compression = info["compression_format"] ? info["compression_format"].as<std::string>("") : "";
  const std::string mode = info["compression_mode"] ? info["compression_mode"].as<std::string>("") : "";
  if (!compression.empty()) {
    if (compression != "zstd") throw FileError(metadata, "compression '" + Printable(compression) + "' is not zstd");
    if (mode == "MESSAGE") {
      plan.message_compression = true;
    } else {
      throw FileError(metadata, "files compressed whole (compression_mode " + Printable(mode) +
                                    ") are not read: decompress them first (zstd -d)");
    }
  }
  const YAML::Node paths = info["relative_file_paths"];
  if (!paths || !paths.IsSequence() || paths.size() == 0) throw FileError(metadata, "no relative_file_paths");
  // Each file inside the folder once: by its path with links resolved (a
  // link out of the folder is outside it; "b..0.db3" is a name, not a way up).
  std::error_code error;
  const fs::path inside = fs::weakly_canonical(fs::absolute(folder), error);
  std::vector<fs::path> seen;
  for (const YAML::Node& entry : paths) {
    if (!entry.IsScalar()) throw FileError(metadata, "relative_file_paths holds a non-string");
    const std::string name = entry.as<std::string>();
    const fs::path resolved = fs::weakly_canonical(inside / name, error);
    const fs::path relative = resolved.lexically_relative(inside);
    if (name.empty() || fs::path(name).is_absolute() || error || relative.empty() || *relative.begin() == ".." ||
        relative == ".") {
      throw FileError(metadata, "file '" + Printable(name) + "' is not inside the bag's folder");
    }
    if (std::find(seen.begin(), seen.end(), resolved) != seen.end()) {
      throw FileError(metadata, "file '" + Printable(name) + "' is listed twice in relative_file_paths");
    }
    seen.push_back(resolved);
    plan.files.push_back((fs::path(folder) / name).string());
  }
  return plan;
}

// One file's count and span of a topic added to the listing of a bag's files.
void AddToListing(std::map<std::string, BagTopic>& listing, const std::string& name, const std::string& type,
                  std::size_t messages, std::pair<double, double> span) {
  BagTopic& t = listing[name];
  t.name = name;
  t.type = type;
  if (messages == 0) return;
  t.first = t.messages == 0 ? span.first : std::min(t.first, span.first);
  t.last = std::max(t.last, span.second);
  t.messages += messages;
}

void ForEachInFile(const std::string& path, const std::string& topic, bool message_compression,
                   const std::function<void(const Ros2Message&)>& visit, std::map<std::string, BagTopic>* listing) {
  const BagFormat format = DetectBagFormat(path);
  std::vector<std::uint8_t> decompressed;
  const auto deliver = [&](Ros2Message message, const std::string& source) {
    if (message_compression) {
      DecompressMessage(message.data, message.size, source, decompressed);
      message.data = decompressed.data();
      message.size = decompressed.size();
    }
    visit(message);
  };
  if (format == BagFormat::kMcap) {
    McapReader reader(path);
    if (listing != nullptr) {
      // Names, types and counts from the reader (the summary's when there is
      // one); the time spans from one pass over the messages.
      std::map<std::string, std::pair<double, double>> spans;
      reader.ForEachMessage([&](const McapMessage& m) {
        const double t = double(m.log_time) * 1e-9;
        auto [it, fresh] = spans.try_emplace(m.channel->topic, t, t);
        if (!fresh) it->second = {std::min(it->second.first, t), std::max(it->second.second, t)};
      });
      for (const McapChannel& channel : reader.channels()) {
        const auto span = spans.find(channel.topic);
        AddToListing(*listing, channel.topic, channel.schema_name, channel.message_count,
                     span == spans.end() ? std::make_pair(0.0, 0.0) : span->second);
      }
      return;
    }
    std::size_t index = 0;
    reader.ForEachMessage([&](const McapMessage& m) {
      if (!topic.empty() && m.channel->topic != topic) return;
      if (m.channel->message_encoding != "cdr") {
        throw FileError(path, "topic '" + Printable(m.channel->topic) + "' is " +
                                  Printable(m.channel->message_encoding) + ", not cdr");
      }
      if (m.log_time > std::uint64_t(std::numeric_limits<std::int64_t>::max())) {
        throw FileError(path, "a message's log time is past 2^63 ns");
      }
      deliver({&m.channel->topic, &m.channel->schema_name, std::int64_t(m.log_time), m.data, m.size},
              path + ":" + m.channel->topic + "#" + std::to_string(index++));
    });
    return;
  }
  if (format != BagFormat::kSqlite3) throw FileError(path, "not a ROS 2 bag file (sqlite3 or MCAP)");
  Database db(path, SQLITE_OPEN_READONLY);
  const std::vector<SqliteTopic> topics = SqliteTopics(db, path);
  if (listing != nullptr) {
    Database::Statement counts(
        db, "SELECT topic_id, count(*), min(timestamp), max(timestamp) FROM messages GROUP BY topic_id");
    std::map<std::int64_t, std::array<std::int64_t, 3>> by_topic;
    while (counts.Step()) by_topic[counts.Int(0)] = {counts.Int(1), counts.Int(2), counts.Int(3)};
    for (const SqliteTopic& t : topics) {
      const auto found = by_topic.find(t.id);
      if (found == by_topic.end()) {
        AddToListing(*listing, t.name, t.type, 0, {0.0, 0.0});
      } else {
        AddToListing(*listing, t.name, t.type, std::size_t(found->second[0]),
                     {double(found->second[1]) * 1e-9, double(found->second[2]) * 1e-9});
      }
    }
    return;
  }
  for (const SqliteTopic& t : topics) {
    if (!topic.empty() && t.name != topic) continue;
    if (t.format != "cdr") {
      throw FileError(path, "topic '" + Printable(t.name) + "' is " + Printable(t.format) + ", not cdr");
    }
    Database::Statement query(db, "SELECT timestamp, data FROM messages WHERE topic_id = ? ORDER BY timestamp, id");
    query.Bind(1, t.id);
    std::size_t index = 0;
    while (query.Step()) {
      Ros2Message message{&t.name, &t.type, query.Int(0), nullptr, 0};
      message.data = query.Blob(1, message.size);
      deliver(message, path + ":" + t.name + "#" + std::to_string(index++));
    }
  }
}

// The files of a bag: a folder's in metadata.yaml's order, or the one file.
FolderPlan PlanOf(const std::string& path) {
  const BagFormat format = DetectBagFormat(path);
  if (format == BagFormat::kRos1) throw FileError(path, "a ROS1 bag, not a ROS 2 one");
  if (format == BagFormat::kRos2Folder) return ReadFolder(path);
  return {{path}, false};
}

}  // namespace

BagFormat DetectBagFormat(const std::string& path) {
  std::error_code error;
  if (fs::is_directory(path, error)) {
    if (fs::exists(fs::path(path) / "metadata.yaml", error)) return BagFormat::kRos2Folder;
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

void ForEachRos2Message(const std::string& path, const std::string& topic,
                        const std::function<void(const Ros2Message&)>& visit) {
  const FolderPlan plan = PlanOf(path);
  std::size_t seen = 0;
  for (const std::string& file : plan.files) {
    ForEachInFile(
        file, topic, plan.message_compression,
        [&](const Ros2Message& m) {
          ++seen;
          visit(m);
        },
        nullptr);
  }
  if (seen == 0 && !topic.empty()) throw FileError(path, "no messages on topic '" + Printable(topic) + "'");
}

std::vector<BagTopic> ListRos2Topics(const std::string& path) {
  const FolderPlan plan = PlanOf(path);
  std::map<std::string, BagTopic> topics;
  for (const std::string& file : plan.files) ForEachInFile(file, "", false, nullptr, &topics);
  std::vector<BagTopic> result;
  for (auto& entry : topics) result.push_back(entry.second);
  return result;
}

// ---------------------------------------------------------------------------
// Writing.

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
