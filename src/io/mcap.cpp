// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/io/mcap.hpp"

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <tuple>
#include <utility>

#include "radargauss/error.hpp"
#include "radargauss/io/read_file.hpp"

namespace radargauss {

namespace {

constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr std::uint64_t kRecordHeader = 9;                   // opcode, length
constexpr std::uint64_t kFooterRecord = kRecordHeader + 20;  // summary start, summary offset start, CRC

enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

std::uint32_t Crc(std::uint32_t crc, const std::uint8_t* data, std::size_t size) {
  while (size > 0) {  // zlib's crc32 takes a uInt length
    const std::size_t n = std::min<std::size_t>(size, 1u << 30);
    crc = std::uint32_t(crc32(crc, data, uInt(n)));
    data += n;
    size -= n;
  }
  return crc;
}

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

// The decompressed records of a chunk, `size` bytes exactly.
std::vector<std::uint8_t> Decompress(const std::string& compression, const std::uint8_t* data, std::size_t size,
                                     std::uint64_t uncompressed_size, const std::string& path) {
  if (uncompressed_size > kMaxMcapChunkBytes) {
    throw FileError(path, "a chunk of " + std::to_string(uncompressed_size) + " bytes uncompressed is past the " +
                              std::to_string(kMaxMcapChunkBytes >> 20) + " MiB limit");
  }
  // A zstd frame states its content size: a chunk that disagrees is refused
  // before its buffer is allocated.
  if (compression == "zstd") {
    const unsigned long long content = ZSTD_getFrameContentSize(data, size);
    if (content == ZSTD_CONTENTSIZE_ERROR) throw FileError(path, "a zstd chunk is not a zstd frame");
    if (content != ZSTD_CONTENTSIZE_UNKNOWN && content != uncompressed_size) {
      throw FileError(path, "a zstd chunk's frame holds " + std::to_string(content) + " bytes, the chunk states " +
                                std::to_string(uncompressed_size));
    }
  }
  if (compression.empty() && size != uncompressed_size) {
    throw FileError(path, "an uncompressed chunk's sizes disagree");
  }
  std::vector<std::uint8_t> out(static_cast<std::size_t>(uncompressed_size));
  if (compression.empty()) {
    std::copy(data, data + size, out.begin());
  } else if (compression == "zstd") {
    const std::size_t n = ZSTD_decompress(out.data(), out.size(), data, size);
    if (ZSTD_isError(n) || n != out.size()) {
      throw FileError(path, std::string("a zstd chunk does not decompress to its size: ") +
                                (ZSTD_isError(n) ? ZSTD_getErrorName(n) : "size differs"));
    }
  } else if (compression == "lz4") {
    LZ4F_dctx* context = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION))) {
      throw FileError(path, "cannot start lz4 decompression");
    }
    std::size_t written = 0, read = 0;
    std::size_t status = 1;
    while (status != 0 && read < size) {
      std::size_t out_size = out.size() - written;
      std::size_t in_size = size - read;
      status = LZ4F_decompress(context, out.data() + written, &out_size, data + read, &in_size, nullptr);
      if (LZ4F_isError(status)) break;
      written += out_size;
      read += in_size;
      if (out_size == 0 && in_size == 0) break;  // no progress: the output is full
    }
    LZ4F_freeDecompressionContext(context);
    if (LZ4F_isError(status) || status != 0 || written != out.size()) {
      throw FileError(path, "an lz4 chunk does not decompress to its size");
    }
  } else {
    throw FileError(path, "chunk compression '" + Printable(compression) + "' is not zstd, lz4 or none");
  }
  return out;
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

void McapReader::ForEachMessage(const std::function<void(const McapMessage&)>& visit) { Scan(&visit); }

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
    if (visit == nullptr) {
      ++channel->second.message_count;
    } else {
      message.channel = &channel->second;
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
    if (opcode != kChunk) continue;
    Cursor c(body.data(), body.size(), path_, "chunk");
    c.Bytes(16);  // message start and end times
    const auto uncompressed_size = c.Int<std::uint64_t>();
    const auto uncompressed_crc = c.Int<std::uint32_t>();
    const std::string compression = c.String();
    const auto records_size = c.Int<std::uint64_t>();
    const std::uint8_t* compressed = c.Bytes(records_size);
    const std::vector<std::uint8_t> records =
        Decompress(compression, compressed, std::size_t(records_size), uncompressed_size, path_);
    if (uncompressed_crc != 0 && Crc(0, records.data(), records.size()) != uncompressed_crc) {
      throw FileError(path_, "a chunk's CRC does not match (offset " + std::to_string(position) + ")");
    }
    Cursor inner(records.data(), records.size(), path_, "chunk");
    while (inner.remaining() > 0) {
      const auto inner_opcode = inner.Int<std::uint8_t>();
      const auto inner_length = inner.Int<std::uint64_t>();
      const std::uint8_t* inner_body = inner.Bytes(inner_length);
      if (inner_opcode == kSchema) AddSchema(inner_body, std::size_t(inner_length));
      if (inner_opcode == kChannel) AddChannel(inner_body, std::size_t(inner_length));
      if (inner_opcode == kMessage) on_message(inner_body, std::size_t(inner_length));
    }
  }
  if (first) throw FileError(path_, "an MCAP file without a header record");
}

// ---------------------------------------------------------------------------
// Writing.

struct McapWriter::Impl {
  std::ostream& out;
  McapWriterOptions options;
  std::uint64_t position = 0;
  std::uint32_t data_crc = 0;
  bool finished = false;
  struct SchemaRecord {
    std::uint16_t id;
    std::string name, encoding, data;
  };
  struct ChannelRecord {
    std::uint16_t id, schema_id;
    std::string topic, encoding;
  };
  std::vector<SchemaRecord> schemas;
  std::vector<ChannelRecord> channels;
  std::map<std::uint16_t, std::uint64_t> counts;
  std::uint64_t message_count = 0, start_time = ~std::uint64_t(0), end_time = 0;
  // The open chunk.
  std::vector<std::uint8_t> chunk;
  std::uint64_t chunk_start = ~std::uint64_t(0), chunk_end = 0;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> index;  // channel: (time, offset)
  std::vector<std::vector<std::uint8_t>> chunk_indexes;                                 // record bodies

  Impl(std::ostream& o, const McapWriterOptions& opts) : out(o), options(opts) {}

  static void Put(std::vector<std::uint8_t>& b, std::uint64_t value, int bytes) {
    for (int i = 0; i < bytes; ++i) b.push_back(std::uint8_t(value >> (8 * i)));
  }
  static void PutString(std::vector<std::uint8_t>& b, const std::string& s) {
    Put(b, s.size(), 4);
    b.insert(b.end(), s.begin(), s.end());
  }
  static std::vector<std::uint8_t> Record(std::uint8_t opcode, const std::vector<std::uint8_t>& body) {
    std::vector<std::uint8_t> r;
    r.reserve(body.size() + kRecordHeader);
    r.push_back(opcode);
    Put(r, body.size(), 8);
    r.insert(r.end(), body.begin(), body.end());
    return r;
  }
  void Emit(const std::uint8_t* data, std::size_t size, bool in_data) {
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    if (in_data) data_crc = Crc(data_crc, data, size);
    position += size;
  }
  void Emit(const std::vector<std::uint8_t>& bytes, bool in_data = true) { Emit(bytes.data(), bytes.size(), in_data); }

  std::vector<std::uint8_t> SchemaBody(const SchemaRecord& s) const {
    std::vector<std::uint8_t> b;
    Put(b, s.id, 2);
    PutString(b, s.name);
    PutString(b, s.encoding);
    PutString(b, s.data);
    return b;
  }
  std::vector<std::uint8_t> ChannelBody(const ChannelRecord& c) const {
    std::vector<std::uint8_t> b;
    Put(b, c.id, 2);
    Put(b, c.schema_id, 2);
    PutString(b, c.topic);
    PutString(b, c.encoding);
    Put(b, 0, 4);  // no metadata
    return b;
  }
  // A record into the open chunk, or straight into the file.
  void Data(const std::vector<std::uint8_t>& record) {
    if (options.chunked) {
      chunk.insert(chunk.end(), record.begin(), record.end());
    } else {
      Emit(record);
    }
  }
  void CloseChunk() {
    if (chunk.empty()) return;
    std::vector<std::uint8_t> compressed;
    std::string compression;
    if (options.compression == McapCompression::kZstd) {
      compression = "zstd";
      compressed.resize(ZSTD_compressBound(chunk.size()));
      const std::size_t n = ZSTD_compress(compressed.data(), compressed.size(), chunk.data(), chunk.size(), 3);
      if (ZSTD_isError(n)) throw DataError(std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
      compressed.resize(n);
    } else if (options.compression == McapCompression::kLz4) {
      compression = "lz4";
      compressed.resize(LZ4F_compressFrameBound(chunk.size(), nullptr));
      const std::size_t n =
          LZ4F_compressFrame(compressed.data(), compressed.size(), chunk.data(), chunk.size(), nullptr);
      if (LZ4F_isError(n)) throw DataError("lz4 compression failed");
      compressed.resize(n);
    } else {
      compressed = chunk;
    }
    std::vector<std::uint8_t> body;
    Put(body, chunk_start, 8);
    Put(body, chunk_end, 8);
    Put(body, chunk.size(), 8);
    Put(body, Crc(0, chunk.data(), chunk.size()), 4);
    PutString(body, compression);
    Put(body, compressed.size(), 8);
    body.insert(body.end(), compressed.begin(), compressed.end());
    const std::uint64_t chunk_offset = position;
    Emit(Record(kChunk, body));
    const std::uint64_t chunk_length = position - chunk_offset;
    // Its message indexes, then its chunk index for the summary.
    std::vector<std::uint8_t> offsets;
    const std::uint64_t indexes_start = position;
    for (const auto& [channel, entries] : index) {
      Put(offsets, channel, 2);
      Put(offsets, position, 8);
      std::vector<std::uint8_t> mi;
      Put(mi, channel, 2);
      Put(mi, entries.size() * 16, 4);
      for (const auto& [time, offset] : entries) {
        Put(mi, time, 8);
        Put(mi, offset, 8);
      }
      Emit(Record(kMessageIndex, mi));
    }
    std::vector<std::uint8_t> ci;
    Put(ci, chunk_start, 8);
    Put(ci, chunk_end, 8);
    Put(ci, chunk_offset, 8);
    Put(ci, chunk_length, 8);
    Put(ci, offsets.size(), 4);
    ci.insert(ci.end(), offsets.begin(), offsets.end());
    Put(ci, position - indexes_start, 8);
    PutString(ci, compression);
    Put(ci, compressed.size(), 8);
    Put(ci, chunk.size(), 8);
    chunk_indexes.push_back(ci);
    chunk.clear();
    index.clear();
    chunk_start = ~std::uint64_t(0);
    chunk_end = 0;
  }
};

McapWriter::McapWriter(std::ostream& out, const McapWriterOptions& options)
    : impl_(std::make_shared<Impl>(out, options)) {
  impl_->Emit(kMagic, sizeof(kMagic), true);
  std::vector<std::uint8_t> header;
  Impl::PutString(header, options.profile);
  Impl::PutString(header, "radargauss");
  impl_->Emit(Impl::Record(kHeader, header));
}

std::uint16_t McapWriter::AddSchema(const std::string& name, const std::string& encoding, const std::string& data) {
  const auto id = std::uint16_t(impl_->schemas.size() + 1);
  impl_->schemas.push_back({id, name, encoding, data});
  impl_->Data(Impl::Record(kSchema, impl_->SchemaBody(impl_->schemas.back())));
  return id;
}

std::uint16_t McapWriter::AddChannel(const std::string& topic, std::uint16_t schema_id,
                                     const std::string& message_encoding) {
  const auto id = std::uint16_t(impl_->channels.size() + 1);
  impl_->channels.push_back({id, schema_id, topic, message_encoding});
  impl_->Data(Impl::Record(kChannel, impl_->ChannelBody(impl_->channels.back())));
  return id;
}

void McapWriter::Write(std::uint16_t channel, std::uint64_t log_time, std::uint64_t publish_time,
                       const std::vector<std::uint8_t>& data) {
  Impl& w = *impl_;
  std::vector<std::uint8_t> body;
  body.reserve(data.size() + 22);
  Impl::Put(body, channel, 2);
  Impl::Put(body, w.counts[channel], 4);  // sequence
  Impl::Put(body, log_time, 8);
  Impl::Put(body, publish_time, 8);
  body.insert(body.end(), data.begin(), data.end());
  ++w.counts[channel];
  ++w.message_count;
  w.start_time = std::min(w.start_time, log_time);
  w.end_time = std::max(w.end_time, log_time);
  if (w.options.chunked) {
    w.index[channel].push_back({log_time, w.chunk.size()});
    w.chunk_start = std::min(w.chunk_start, log_time);
    w.chunk_end = std::max(w.chunk_end, log_time);
  }
  w.Data(Impl::Record(kMessage, body));
  if (w.options.chunked && w.chunk.size() >= w.options.chunk_bytes) w.CloseChunk();
}

void McapWriter::Finish() {
  Impl& w = *impl_;
  if (w.finished) return;
  w.finished = true;
  w.CloseChunk();
  std::vector<std::uint8_t> data_end;
  Impl::Put(data_end, w.data_crc, 4);
  w.Emit(Impl::Record(kDataEnd, data_end), false);
  // The summary: schemas, channels, statistics, chunk indexes; then their offsets.
  const std::uint64_t summary_start = w.position;
  std::uint32_t summary_crc = 0;
  const auto emit_summary = [&](const std::vector<std::uint8_t>& record) {
    summary_crc = Crc(summary_crc, record.data(), record.size());
    w.Emit(record, false);
  };
  std::vector<std::tuple<std::uint8_t, std::uint64_t, std::uint64_t>> groups;
  const auto group = [&](std::uint8_t opcode, const std::vector<std::vector<std::uint8_t>>& bodies) {
    if (bodies.empty()) return;
    const std::uint64_t start = w.position;
    for (const auto& body : bodies) emit_summary(Impl::Record(opcode, body));
    groups.emplace_back(opcode, start, w.position - start);
  };
  std::vector<std::vector<std::uint8_t>> bodies;
  for (const auto& s : w.schemas) bodies.push_back(w.SchemaBody(s));
  group(kSchema, bodies);
  bodies.clear();
  for (const auto& c : w.channels) bodies.push_back(w.ChannelBody(c));
  group(kChannel, bodies);
  std::vector<std::uint8_t> statistics;
  Impl::Put(statistics, w.message_count, 8);
  Impl::Put(statistics, w.schemas.size(), 2);
  Impl::Put(statistics, w.channels.size(), 4);
  Impl::Put(statistics, 0, 4);  // attachments
  Impl::Put(statistics, 0, 4);  // metadata
  Impl::Put(statistics, w.chunk_indexes.size(), 4);
  Impl::Put(statistics, w.message_count ? w.start_time : 0, 8);
  Impl::Put(statistics, w.end_time, 8);
  Impl::Put(statistics, w.counts.size() * 10, 4);
  for (const auto& [channel, count] : w.counts) {
    Impl::Put(statistics, channel, 2);
    Impl::Put(statistics, count, 8);
  }
  group(kStatistics, {statistics});
  group(kChunkIndex, w.chunk_indexes);
  const std::uint64_t offsets_start = w.position;
  for (const auto& [opcode, start, length] : groups) {
    std::vector<std::uint8_t> body;
    body.push_back(opcode);
    Impl::Put(body, start, 8);
    Impl::Put(body, length, 8);
    emit_summary(Impl::Record(kSummaryOffset, body));
  }
  std::vector<std::uint8_t> footer = {kFooter};
  Impl::Put(footer, 20, 8);
  Impl::Put(footer, summary_start, 8);
  Impl::Put(footer, offsets_start, 8);
  summary_crc = Crc(summary_crc, footer.data(), footer.size());
  Impl::Put(footer, summary_crc, 4);
  w.Emit(footer, false);
  w.Emit(kMagic, sizeof(kMagic), false);
}

}  // namespace radargauss
