// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/rosbag2.hpp"

#include <zstd.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>

#include "decompress.hpp"
#include "sqlite_database.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"
#include "radargauss/io/ros2_messages.hpp"
#include "radargauss/io/yaml_file.hpp"

namespace radargauss {

namespace {

namespace fs = std::filesystem;

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

}  // namespace radargauss
