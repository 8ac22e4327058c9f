// SPDX-License-Identifier: BSD-3-Clause
// MCAP files (https://mcap.dev/spec, version 0), the default storage of
// rosbag2 (docs/design/formats.md, "ROS 2 bags"): read record by record from the
// file, chunked or not, chunks uncompressed, zstd or lz4 (Debian's libzstd
// and liblz4), every CRC that the file states checked; and written with
// chunks, message indexes and a summary (schemas, channels, statistics,
// chunk indexes) that other MCAP readers use. Every length is checked
// against what holds it and a chunk may decompress to at most
// kMaxMcapChunkBytes: a file that lies gets one DataError naming it.
//
//   McapReader reader(path);
//   for (const McapChannel& c : reader.channels()) ...
//   reader.ForEachMessage([&](const McapMessage& m) { ... });        // all, in file order
//   reader.Read({{"/imu/data"}}, [&](const McapMessage& m) { ... });  // by the chunk index
#pragma once

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace radargauss {

inline constexpr std::uint64_t kMaxMcapChunkBytes = std::uint64_t(1) << 30;  // 1 GiB

// Whether `path` starts with MCAP's magic bytes.
bool IsMcapFile(const std::string& path);

struct McapChannel {
  std::uint16_t id = 0;
  std::string topic;
  std::string message_encoding;     // "cdr" for ROS 2
  std::string schema_name;          // the message type: "sensor_msgs/msg/PointCloud2"
  std::string schema_encoding;      // "ros2msg"
  std::uint64_t message_count = 0;  // from the summary's statistics, or counted by ScanCounts
};

// One message; `data` lives until the visitor returns.
struct McapMessage {
  const McapChannel* channel = nullptr;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;      // ns
  std::uint64_t publish_time = 0;  // ns
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
};

// What McapReader::Read delivers: the messages of `topics` (every topic
// when empty) whose log time lies in [start, end] (ns).
struct McapReadOptions {
  std::vector<std::string> topics;
  std::uint64_t start = 0;
  std::uint64_t end = std::numeric_limits<std::uint64_t>::max();
};

// A chunk as the summary's chunk index states it.
struct McapChunkIndex {
  std::uint64_t start_time = 0, end_time = 0;  // ns: its first and last message's log time
  std::uint64_t offset = 0, length = 0;        // of the chunk record, in the file
  std::vector<std::uint16_t> channels;         // those with a message index (empty: not stated)
};

class McapReader {
 public:
  // Opens the file and checks both magics; reads the summary section when
  // the footer points to one (its CRC checked), else scans the data section
  // once for the channels and their counts.
  explicit McapReader(const std::string& path);

  // Every channel, in id order, with its message count.
  const std::vector<McapChannel>& channels() const { return channel_list_; }
  // Calls visit for every message in file order (chunks decompressed one at
  // a time), checking each chunk's CRC and, over a whole pass, the data
  // section's. Throws DataError naming the file for any malformed record.
  void ForEachMessage(const std::function<void(const McapMessage&)>& visit);
  // Calls visit for every message the options admit, in log-time order.
  // With the summary's chunk indexes, only the chunks whose index admits a
  // topic and overlaps the range are read (each CRC checked); chunks whose
  // times overlap are read together and merged. Without them, one pass in
  // file order as ForEachMessage.
  void Read(const McapReadOptions& options, const std::function<void(const McapMessage&)>& visit);
  const std::vector<McapChunkIndex>& chunk_indexes() const { return chunk_indexes_; }
  // Chunks decompressed and chunks skipped by their index, over every pass so far.
  std::size_t chunks_read() const { return chunks_read_; }
  std::size_t chunks_skipped() const { return chunks_skipped_; }

 private:
  void ReadSummary(std::uint64_t summary_start, std::uint64_t footer_offset);
  void Scan(const std::function<void(const McapMessage&)>* visit);
  void AddSchema(const std::uint8_t* body, std::size_t size);
  void AddChannel(const std::uint8_t* body, std::size_t size);
  void AddChunkIndex(const std::uint8_t* body, std::size_t size);
  // A chunk record's body decompressed (its CRC checked), `position` naming it.
  std::vector<std::uint8_t> ChunkRecords(const std::uint8_t* body, std::size_t size, std::uint64_t position);
  // Calls on_message for each message record among `records` (schemas and
  // channels among them added first).
  void ForEachRecord(const std::vector<std::uint8_t>& records,
                     const std::function<void(const std::uint8_t*, std::size_t)>& on_message);
  McapMessage ParseMessage(const std::uint8_t* data, std::size_t size);

  std::string path_;
  std::ifstream file_;
  std::uint64_t size_ = 0;
  std::uint64_t data_end_ = 0;  // where the data section's records end (the footer's or the summary's start)
  struct Schema {
    std::string name, encoding;
  };
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, McapChannel> channels_;
  std::vector<McapChannel> channel_list_;
  std::vector<McapChunkIndex> chunk_indexes_;
  std::size_t chunks_read_ = 0, chunks_skipped_ = 0;
};

enum class McapCompression { kNone, kZstd, kLz4 };

struct McapWriterOptions {
  bool chunked = true;
  McapCompression compression = McapCompression::kZstd;  // of the chunks
  std::size_t chunk_bytes = std::size_t(1) << 20;        // a chunk closes past this much
  std::string profile = "ros2";
};

// Writes an MCAP file to `out` (binary): the header at construction, the
// data, and at Finish the summary and footer. Channels and schemas are
// written before their first message.
class McapWriter {
 public:
  McapWriter(std::ostream& out, const McapWriterOptions& options = {});
  std::uint16_t AddSchema(const std::string& name, const std::string& encoding, const std::string& data);
  std::uint16_t AddChannel(const std::string& topic, std::uint16_t schema_id,
                           const std::string& message_encoding = "cdr");
  void Write(std::uint16_t channel, std::uint64_t log_time, std::uint64_t publish_time,
             const std::vector<std::uint8_t>& data);
  void Finish();

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace radargauss
