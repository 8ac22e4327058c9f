// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/mcap.hpp"

#include <algorithm>
#include <cstring>
#include <tuple>
#include <utility>

#include "decompress.hpp"
#include "radargauss/core/error.hpp"
#include "radargauss/io/mcap_records.hpp"
#include "radargauss/core/read_file.hpp"

namespace radargauss {

using namespace mcap;

namespace {

// Little-endian fields of one record's body, each read checked against its end.
class Cursor {
 public:
  Cursor(const std::uint8_t* data, std::size_t size, const std::string& path, const char* record)
      : data_(data), size_(size), path_(path), record_(record) {}
  template <typename T>
  T Int() {
    Need(sizeof(T));
    T value = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) value |= T(data_[pos_ + i]) << (8 * i);
    pos_ += sizeof(T);
    return value;
  }
  std::string String() {
    const std::uint32_t n = Int<std::uint32_t>();
    Need(n);
    std::string s(reinterpret_cast<const char*>(data_ + pos_), n);
    pos_ += n;
    return s;
  }
  // `n` bytes, in place.
  const std::uint8_t* Bytes(std::uint64_t n) {
    Need(n);
    const std::uint8_t* p = data_ + pos_;
    pos_ += std::size_t(n);
    return p;
  }
  std::size_t remaining() const { return size_ - pos_; }

 private:
  void Need(std::uint64_t n) const {
    if (n > size_ - pos_) throw FileError(path_, std::string(record_) + " record is shorter than its fields");
  }
  const std::uint8_t* data_;
  std::size_t size_, pos_ = 0;
  const std::string& path_;
  const char* record_;
};

// The decompressed records of a chunk, `uncompressed_size` bytes exactly
// (streamed: a size the chunk states and its data do not hold is refused
// before it is allocated).
std::vector<std::uint8_t> Decompress(const std::string& compression, const std::uint8_t* data, std::size_t size,
                                     std::uint64_t uncompressed_size, const std::string& path) {
  if (compression.empty()) {
    if (size != uncompressed_size) throw FileError(path, "an uncompressed chunk's sizes disagree");
    return std::vector<std::uint8_t>(data, data + size);
  }
  if (compression != "zstd" && compression != "lz4") {
    throw FileError(path, "chunk compression '" + Printable(compression) + "' is not zstd, lz4 or none");
  }
  return DecompressFrame(compression == "zstd" ? Codec::kZstd : Codec::kLz4, data, size, uncompressed_size,
                         kMaxMcapChunkBytes, path, "a " + compression + " chunk");
}

}  // namespace

bool IsMcapFile(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  char magic[8];
  return file.read(magic, 8) && std::memcmp(magic, kMagic, 8) == 0;
}

McapReader::McapReader(const std::string& path) : path_(path) {
  CheckRegularInputFile(path, "MCAP file");
  file_.open(path, std::ios::binary | std::ios::ate);
  if (!file_) throw FileError(path, "cannot open MCAP file");
  size_ = std::uint64_t(file_.tellg());
  if (size_ < 2 * sizeof(kMagic) + kFooterRecord) throw FileError(path, "too short for an MCAP file");
  std::uint8_t head[8], tail[8], footer[kFooterRecord];
  file_.seekg(0);
  file_.read(reinterpret_cast<char*>(head), 8);
  file_.seekg(std::streamoff(size_ - 8));
  file_.read(reinterpret_cast<char*>(tail), 8);
  const std::uint64_t footer_offset = size_ - 8 - kFooterRecord;
  file_.seekg(std::streamoff(footer_offset));
  file_.read(reinterpret_cast<char*>(footer), kFooterRecord);
  if (!file_ || std::memcmp(head, kMagic, 8) != 0) throw FileError(path, "not an MCAP file (no magic at its start)");
  if (std::memcmp(tail, kMagic, 8) != 0) throw FileError(path, "MCAP file is truncated (no magic at its end)");
  Cursor cursor(footer, kFooterRecord, path_, "footer");
  const auto opcode = cursor.Int<std::uint8_t>();
  const auto length = cursor.Int<std::uint64_t>();
  if (opcode != kFooter || length != 20) throw FileError(path, "MCAP file is truncated (no footer before its end)");
  const auto summary_start = cursor.Int<std::uint64_t>();
  const auto summary_offset_start = cursor.Int<std::uint64_t>();
  const auto summary_crc = cursor.Int<std::uint32_t>();
  if (summary_start > footer_offset || summary_offset_start > footer_offset ||
      (summary_start != 0 && summary_start < sizeof(kMagic)) ||
      (summary_offset_start != 0 && summary_offset_start < summary_start)) {
    throw FileError(path, "the footer points outside the file");
  }
  data_end_ = summary_start != 0 ? summary_start : footer_offset;
  if (summary_start != 0) {
    if (summary_crc != 0) {
      // The summary and the footer up to its CRC.
      std::vector<std::uint8_t> bytes(std::size_t(footer_offset + kRecordHeader + 16 - summary_start));
      file_.seekg(std::streamoff(summary_start));
      file_.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size()));
      if (!file_ || Crc(0, bytes.data(), bytes.size()) != summary_crc) {
        throw FileError(path, "the summary section's CRC does not match");
      }
    }
    ReadSummary(summary_start, summary_offset_start != 0 ? summary_offset_start : footer_offset);
  } else {
    Scan(nullptr);
  }
  for (auto& entry : channels_) channel_list_.push_back(entry.second);
}

void McapReader::AddSchema(const std::uint8_t* body, std::size_t size) {
  Cursor c(body, size, path_, "schema");
  const auto id = c.Int<std::uint16_t>();
  Schema schema;
  schema.name = c.String();
  schema.encoding = c.String();
  if (id == 0) throw FileError(path_, "a schema with id 0");
  schemas_[id] = schema;
}

void McapReader::AddChannel(const std::uint8_t* body, std::size_t size) {
  Cursor c(body, size, path_, "channel");
  McapChannel channel;
  channel.id = c.Int<std::uint16_t>();
  const auto schema_id = c.Int<std::uint16_t>();
  channel.topic = c.String();
  channel.message_encoding = c.String();
  if (schema_id != 0) {
    const auto schema = schemas_.find(schema_id);
    if (schema == schemas_.end()) {
      throw FileError(path_, "channel '" + Printable(channel.topic) + "' names schema " + std::to_string(schema_id) +
                                 ", which the file has not defined before it");
    }
    channel.schema_name = schema->second.name;
    channel.schema_encoding = schema->second.encoding;
  }
  const auto known = channels_.find(channel.id);
  if (known != channels_.end()) channel.message_count = known->second.message_count;
  channels_[channel.id] = channel;
}

void McapReader::ReadSummary(std::uint64_t start, std::uint64_t end) {
  file_.seekg(std::streamoff(start));
  std::vector<std::uint8_t> bytes(std::size_t(end - start));
  file_.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size()));
  if (!file_) throw FileError(path_, "cannot read the summary section");
  bool counted = false;
  std::map<std::uint16_t, std::uint64_t> counts;
  Cursor records(bytes.data(), bytes.size(), path_, "summary");
  while (records.remaining() > 0) {
    const auto opcode = records.Int<std::uint8_t>();
    const auto length = records.Int<std::uint64_t>();
    const std::uint8_t* body = records.Bytes(length);
    if (opcode == kSchema) AddSchema(body, std::size_t(length));
    if (opcode == kChannel) AddChannel(body, std::size_t(length));
    if (opcode == kChunkIndex) AddChunkIndex(body, std::size_t(length));
    if (opcode == kStatistics) {
      Cursor c(body, std::size_t(length), path_, "statistics");
      c.Bytes(8 + 2 + 4 + 4 + 4 + 4 + 8 + 8);
      const auto map_bytes = c.Int<std::uint32_t>();
      Cursor map(c.Bytes(map_bytes), map_bytes, path_, "statistics");
      while (map.remaining() > 0) {
        const auto channel = map.Int<std::uint16_t>();
        counts[channel] = map.Int<std::uint64_t>();
      }
      counted = true;
    }
  }
  if (!counted) {
    Scan(nullptr);
    return;
  }
  for (auto& [id, channel] : channels_) channel.message_count = counts.count(id) ? counts[id] : 0;
}

void McapReader::AddChunkIndex(const std::uint8_t* body, std::size_t size) {
  Cursor c(body, size, path_, "chunk index");
  McapChunkIndex index;
  index.start_time = c.Int<std::uint64_t>();
  index.end_time = c.Int<std::uint64_t>();
  index.offset = c.Int<std::uint64_t>();
  index.length = c.Int<std::uint64_t>();
  const auto map_bytes = c.Int<std::uint32_t>();
  Cursor map(c.Bytes(map_bytes), map_bytes, path_, "chunk index");
  while (map.remaining() > 0) {
    index.channels.push_back(map.Int<std::uint16_t>());
    map.Int<std::uint64_t>();  // where its message index is: not needed to read the chunk
  }
  if (index.start_time > index.end_time) throw FileError(path_, "a chunk index ends before it starts");
  if (index.offset < sizeof(kMagic) || index.length < kRecordHeader || index.offset > data_end_ ||
      index.length > data_end_ - index.offset || index.length - kRecordHeader > kMaxMcapChunkBytes) {
    throw FileError(path_, "a chunk index points outside the data section");
  }
  chunk_indexes_.push_back(std::move(index));
}

void McapReader::ForEachMessage(const std::function<void(const McapMessage&)>& visit) { Scan(&visit); }

McapMessage McapReader::ParseMessage(const std::uint8_t* data, std::size_t size) {
  Cursor c(data, size, path_, "message");
  McapMessage message;
  const auto channel_id = c.Int<std::uint16_t>();
  message.sequence = c.Int<std::uint32_t>();
  message.log_time = c.Int<std::uint64_t>();
  message.publish_time = c.Int<std::uint64_t>();
  message.size = c.remaining();
  message.data = c.Bytes(message.size);
  const auto channel = channels_.find(channel_id);
  if (channel == channels_.end()) {
    throw FileError(path_, "a message on channel " + std::to_string(channel_id) + ", which is not defined before it");
  }
  message.channel = &channel->second;
  return message;
}

std::vector<std::uint8_t> McapReader::ChunkRecords(const std::uint8_t* body, std::size_t size, std::uint64_t position) {
  Cursor c(body, size, path_, "chunk");
  c.Bytes(16);  // message start and end times
  const auto uncompressed_size = c.Int<std::uint64_t>();
  const auto uncompressed_crc = c.Int<std::uint32_t>();
  const std::string compression = c.String();
  const auto records_size = c.Int<std::uint64_t>();
  const std::uint8_t* compressed = c.Bytes(records_size);
  std::vector<std::uint8_t> records =
      Decompress(compression, compressed, std::size_t(records_size), uncompressed_size, path_);
  ++chunks_read_;
  if (uncompressed_crc != 0 && Crc(0, records.data(), records.size()) != uncompressed_crc) {
    throw FileError(path_, "a chunk's CRC does not match (offset " + std::to_string(position) + ")");
  }
  return records;
}

void McapReader::ForEachRecord(const std::vector<std::uint8_t>& records,
                               const std::function<void(const std::uint8_t*, std::size_t)>& on_message) {
  Cursor inner(records.data(), records.size(), path_, "chunk");
  while (inner.remaining() > 0) {
    const auto opcode = inner.Int<std::uint8_t>();
    const auto length = inner.Int<std::uint64_t>();
    const std::uint8_t* body = inner.Bytes(length);
    if (opcode == kSchema) AddSchema(body, std::size_t(length));
    if (opcode == kChannel) AddChannel(body, std::size_t(length));
    if (opcode == kMessage) on_message(body, std::size_t(length));
  }
}

void McapReader::Read(const McapReadOptions& options, const std::function<void(const McapMessage&)>& visit) {
  std::vector<std::uint16_t> wanted;
  for (const auto& [id, channel] : channels_) {
    if (options.topics.empty() ||
        std::find(options.topics.begin(), options.topics.end(), channel.topic) != options.topics.end()) {
      wanted.push_back(id);
    }
  }
  const auto admitted = [&](const McapMessage& m) {
    return std::binary_search(wanted.begin(), wanted.end(), m.channel->id) && m.log_time >= options.start &&
           m.log_time <= options.end;
  };
  if (chunk_indexes_.empty()) {
    const std::function<void(const McapMessage&)> filtered = [&](const McapMessage& m) {
      if (admitted(m)) visit(m);
    };
    Scan(&filtered);
    return;
  }
  // The chunks the index admits, by start time; a chunk whose index states
  // no channels may hold any.
  std::vector<const McapChunkIndex*> chosen;
  for (const McapChunkIndex& chunk : chunk_indexes_) {
    const bool in_range = chunk.end_time >= options.start && chunk.start_time <= options.end;
    const bool has_topic =
        chunk.channels.empty() || std::any_of(chunk.channels.begin(), chunk.channels.end(), [&](std::uint16_t id) {
          return std::binary_search(wanted.begin(), wanted.end(), id);
        });
    if (in_range && has_topic) {
      chosen.push_back(&chunk);
    } else {
      ++chunks_skipped_;
    }
  }
  std::stable_sort(chosen.begin(), chosen.end(), [](const McapChunkIndex* a, const McapChunkIndex* b) {
    return std::tie(a->start_time, a->offset) < std::tie(b->start_time, b->offset);
  });
  // Chunks whose time spans overlap are read together, their messages merged by log time.
  std::vector<std::uint8_t> body;
  for (std::size_t first = 0; first < chosen.size();) {
    std::size_t last = first + 1;
    std::uint64_t end = chosen[first]->end_time;
    while (last < chosen.size() && chosen[last]->start_time <= end) end = std::max(end, chosen[last++]->end_time);
    std::vector<std::vector<std::uint8_t>> groups;
    std::vector<McapMessage> messages;
    for (std::size_t k = first; k < last; ++k) {
      const McapChunkIndex& chunk = *chosen[k];
      std::uint8_t header[kRecordHeader];
      file_.clear();
      file_.seekg(std::streamoff(chunk.offset));
      file_.read(reinterpret_cast<char*>(header), kRecordHeader);
      Cursor h(header, kRecordHeader, path_, "record");
      if (h.Int<std::uint8_t>() != kChunk || h.Int<std::uint64_t>() != chunk.length - kRecordHeader) {
        throw FileError(path_,
                        "a chunk index points to no chunk of its length (offset " + std::to_string(chunk.offset) + ")");
      }
      body.resize(std::size_t(chunk.length - kRecordHeader));
      file_.read(reinterpret_cast<char*>(body.data()), std::streamsize(body.size()));
      if (!file_) throw FileError(path_, "cannot read the chunk at offset " + std::to_string(chunk.offset));
      groups.push_back(ChunkRecords(body.data(), body.size(), chunk.offset));
    }
    for (const std::vector<std::uint8_t>& records : groups) {
      ForEachRecord(records, [&](const std::uint8_t* data, std::size_t size) {
        const McapMessage message = ParseMessage(data, size);
        if (admitted(message)) messages.push_back(message);
      });
    }
    std::stable_sort(messages.begin(), messages.end(),
                     [](const McapMessage& a, const McapMessage& b) { return a.log_time < b.log_time; });
    for (const McapMessage& message : messages) visit(message);
    first = last;
  }
}

// One pass over the data section: schemas and channels as they come, each
// message counted (visit null) or visited; chunks decompressed one at a time.
void McapReader::Scan(const std::function<void(const McapMessage&)>* visit) {
  if (visit == nullptr) {
    for (auto& entry : channels_) entry.second.message_count = 0;
  }
  file_.clear();
  file_.seekg(std::streamoff(sizeof(kMagic)));
  std::uint32_t data_crc = Crc(0, kMagic, sizeof(kMagic));
  std::uint64_t position = sizeof(kMagic);
  std::vector<std::uint8_t> body;
  bool first = true;
  const auto on_message = [&](const std::uint8_t* data, std::size_t size) {
    const McapMessage message = ParseMessage(data, size);
    if (visit == nullptr) {
      ++channels_.at(message.channel->id).message_count;
    } else {
      (*visit)(message);
    }
  };
  while (position < data_end_) {
    std::uint8_t header[kRecordHeader];
    if (data_end_ - position < kRecordHeader) throw FileError(path_, "a record is cut by the end of the data section");
    file_.read(reinterpret_cast<char*>(header), kRecordHeader);
    Cursor h(header, kRecordHeader, path_, "record");
    const auto opcode = h.Int<std::uint8_t>();
    const auto length = h.Int<std::uint64_t>();
    if (length > data_end_ - position - kRecordHeader) {
      throw FileError(path_, "a record of " + std::to_string(length) + " bytes at offset " + std::to_string(position) +
                                 " runs past the end of the data section");
    }
    if (length > kMaxMcapChunkBytes) {
      throw FileError(path_, "a record of " + std::to_string(length) + " bytes is past the " +
                                 std::to_string(kMaxMcapChunkBytes >> 20) + " MiB limit");
    }
    body.resize(std::size_t(length));
    file_.read(reinterpret_cast<char*>(body.data()), std::streamsize(length));
    if (!file_) throw FileError(path_, "cannot read the record at offset " + std::to_string(position));
    if (first && opcode != kHeader) throw FileError(path_, "the first record is not MCAP's header");
    first = false;
    if (opcode == kDataEnd) {
      Cursor c(body.data(), body.size(), path_, "data end");
      const auto stated = c.Int<std::uint32_t>();
      if (stated != 0 && stated != data_crc) throw FileError(path_, "the data section's CRC does not match");
      break;
    }
    data_crc = Crc(Crc(data_crc, header, kRecordHeader), body.data(), body.size());
    position += kRecordHeader + length;
    if (opcode == kSchema) AddSchema(body.data(), body.size());
    if (opcode == kChannel) AddChannel(body.data(), body.size());
    if (opcode == kMessage) on_message(body.data(), body.size());
    if (opcode == kChunk) ForEachRecord(ChunkRecords(body.data(), body.size(), position), on_message);
  }
  if (first) throw FileError(path_, "an MCAP file without a header record");
}

}  // namespace radargauss
