// SPDX-License-Identifier: BSD-3-Clause
// The readers of ROS 2 bags (docs/design/formats.md, "ROS 2 bags"): an MCAP
// file, a sqlite3 file, and a rosbag2 folder of them.

#include <zstd.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>

#include "bag_readers.hpp"
#include "decompress.hpp"
#include "sqlite_database.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/core/read_file.hpp"
#include "radargauss/io/bag_reader.hpp"
#include "radargauss/io/mcap.hpp"
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

std::vector<BagTopic> Listed(const std::map<std::string, BagTopic>& listing) {
  std::vector<BagTopic> result;
  for (const auto& entry : listing) result.push_back(entry.second);
  return result;
}

class McapBag final : public BagReader {
 public:
  explicit McapBag(const std::string& path) : BagReader(path), reader_(path) {}

  std::vector<BagTopic> Topics() override {
    // Names, types and counts from the reader (the summary's when there is
    // one); the time spans from one pass over the messages.
    std::map<std::string, std::pair<double, double>> spans;
    reader_.ForEachMessage([&](const McapMessage& m) {
      const double t = double(m.log_time) * 1e-9;
      auto [it, fresh] = spans.try_emplace(m.channel->topic, t, t);
      if (!fresh) it->second = {std::min(it->second.first, t), std::max(it->second.second, t)};
    });
    std::map<std::string, BagTopic> listing;
    for (const McapChannel& channel : reader_.channels()) {
      const auto span = spans.find(channel.topic);
      AddToListing(listing, channel.topic, channel.schema_name, channel.message_count,
                   span == spans.end() ? std::make_pair(0.0, 0.0) : span->second);
    }
    return Listed(listing);
  }

  BagReadStatistics statistics() const override { return {reader_.chunks_read(), reader_.chunks_skipped()}; }

  void Read(const BagReadOptions& options, const std::function<void(const BagMessage&)>& visit) override {
    if (options.end < 0 || options.end < options.start) return;  // MCAP's log times are unsigned
    const McapReadOptions read{options.topics, std::uint64_t(std::max<std::int64_t>(options.start, 0)),
                               std::uint64_t(options.end)};
    reader_.Read(read, [&](const McapMessage& m) {
      if (m.channel->message_encoding != "cdr") {
        throw FileError(path(), "topic '" + Printable(m.channel->topic) + "' is " +
                                    Printable(m.channel->message_encoding) + ", not cdr");
      }
      if (m.log_time > std::uint64_t(std::numeric_limits<std::int64_t>::max())) {
        throw FileError(path(), "a message's log time is past 2^63 ns");
      }
      visit({&m.channel->topic, &m.channel->schema_name, std::int64_t(m.log_time), m.data, m.size, &CdrCodec()});
    });
  }

 private:
  McapReader reader_;
};

class SqliteBag final : public BagReader {
 public:
  explicit SqliteBag(const std::string& path)
      : BagReader(path), db_(path, SQLITE_OPEN_READONLY), topics_(SqliteTopics(db_, path)) {}

  std::vector<BagTopic> Topics() override {
    Database::Statement counts(
        db_, "SELECT topic_id, count(*), min(timestamp), max(timestamp) FROM messages GROUP BY topic_id");
    std::map<std::int64_t, std::array<std::int64_t, 3>> by_topic;
    while (counts.Step()) by_topic[counts.Int(0)] = {counts.Int(1), counts.Int(2), counts.Int(3)};
    std::map<std::string, BagTopic> listing;
    for (const SqliteTopic& t : topics_) {
      const auto found = by_topic.find(t.id);
      if (found == by_topic.end()) {
        AddToListing(listing, t.name, t.type, 0, {0.0, 0.0});
      } else {
        AddToListing(listing, t.name, t.type, std::size_t(found->second[0]),
                     {double(found->second[1]) * 1e-9, double(found->second[2]) * 1e-9});
      }
    }
    return Listed(listing);
  }

  // One query over the admitted topics, in log-time order (the timestamp index).
  void Read(const BagReadOptions& options, const std::function<void(const BagMessage&)>& visit) override {
    std::map<std::int64_t, const SqliteTopic*> admitted;
    for (const SqliteTopic& t : topics_) {
      if (!options.topics.empty() &&
          std::find(options.topics.begin(), options.topics.end(), t.name) == options.topics.end()) {
        continue;
      }
      if (t.format != "cdr") {
        throw FileError(path(), "topic '" + Printable(t.name) + "' is " + Printable(t.format) + ", not cdr");
      }
      admitted[t.id] = &t;
    }
    if (admitted.empty()) return;
    std::string ids;
    for (std::size_t k = 0; k < admitted.size(); ++k) ids += k == 0 ? "?" : ", ?";
    Database::Statement query(db_, "SELECT topic_id, timestamp, data FROM messages WHERE topic_id IN (" + ids +
                                       ") AND timestamp >= ? AND timestamp <= ? ORDER BY timestamp, id");
    int parameter = 1;
    for (const auto& entry : admitted) query.Bind(parameter++, entry.first);
    query.Bind(parameter++, options.start);
    query.Bind(parameter, options.end);
    while (query.Step()) {
      const SqliteTopic& t = *admitted.at(query.Int(0));
      BagMessage message{&t.name, &t.type, query.Int(1), nullptr, 0, &CdrCodec()};
      message.data = query.Blob(2, message.size);
      visit(message);
    }
  }

 private:
  Database db_;
  std::vector<SqliteTopic> topics_;
};

// A rosbag2 folder: its files in metadata.yaml's order, each read by its own
// reader, messages compressed one by one undone on the way.
class Ros2Folder final : public BagReader {
 public:
  explicit Ros2Folder(const std::string& path) : BagReader(path), plan_(ReadFolder(path)) {
    for (const std::string& file : plan_.files) {
      switch (DetectBagFormat(file)) {
        case BagFormat::kMcap:
          files_.push_back(OpenMcapBag(file));
          break;
        case BagFormat::kSqlite3:
          files_.push_back(OpenSqliteBag(file));
          break;
        default:
          throw FileError(file, "not a ROS 2 bag file (sqlite3 or MCAP)");
      }
    }
  }

  std::vector<BagTopic> Topics() override {
    std::map<std::string, BagTopic> listing;
    for (const auto& file : files_) {
      for (const BagTopic& t : file->Topics()) AddToListing(listing, t.name, t.type, t.messages, {t.first, t.last});
    }
    return Listed(listing);
  }

  BagReadStatistics statistics() const override {
    BagReadStatistics total;
    for (const auto& file : files_) {
      const BagReadStatistics read = file->statistics();
      total.chunks_read += read.chunks_read;
      total.chunks_skipped += read.chunks_skipped;
    }
    return total;
  }

  void Read(const BagReadOptions& options, const std::function<void(const BagMessage&)>& visit) override {
    std::vector<std::uint8_t> decompressed;
    for (const auto& file : files_) {
      std::map<std::string, std::size_t> index;
      file->Read(options, [&](BagMessage message) {
        if (plan_.message_compression) {
          const std::string source =
              file->path() + ":" + *message.topic + "#" + std::to_string(index[*message.topic]++);
          DecompressMessage(message.data, message.size, source, decompressed);
          message.data = decompressed.data();
          message.size = decompressed.size();
        }
        visit(message);
      });
    }
  }

 private:
  FolderPlan plan_;
  std::vector<std::unique_ptr<BagReader>> files_;
};

}  // namespace

std::unique_ptr<BagReader> OpenMcapBag(const std::string& path) { return std::make_unique<McapBag>(path); }
std::unique_ptr<BagReader> OpenSqliteBag(const std::string& path) { return std::make_unique<SqliteBag>(path); }
std::unique_ptr<BagReader> OpenRos2Folder(const std::string& path) { return std::make_unique<Ros2Folder>(path); }

}  // namespace radargauss
