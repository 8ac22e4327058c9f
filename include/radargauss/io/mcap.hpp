// SPDX-License-Identifier: BSD-3-Clause
// MCAP files (https://mcap.dev/spec, version 0), the default storage of
// rosbag2 (docs/design.md, "ROS 2 bags"): read record by record from the
// file, chunked or not, chunks uncompressed, zstd or lz4 (Debian's libzstd
// and liblz4), every CRC that the file states checked; and written with
// chunks, message indexes and a summary (schemas, channels, statistics,
// chunk indexes) that other MCAP readers use. Every length is checked
// against what holds it and a chunk may decompress to at most
// kMaxMcapChunkBytes: a file that lies gets one DataError naming it.
//
//   McapReader reader(path);
//   for (const McapChannel& c : reader.channels()) ...
//   reader.ForEachMessage([&](const McapMessage& m) { ... });
#pragma once

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <functional>
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

 private:
  void ReadSummary(std::uint64_t summary_start, std::uint64_t footer_offset);
  void Scan(const std::function<void(const McapMessage&)>* visit);
  void AddSchema(const std::uint8_t* body, std::size_t size);
  void AddChannel(const std::uint8_t* body, std::size_t size);

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
