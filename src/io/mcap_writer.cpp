// SPDX-License-Identifier: BSD-3-Clause
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <map>
#include <tuple>
#include <utility>

#include "radargauss/core/error.hpp"
#include "radargauss/io/mcap.hpp"
#include "radargauss/io/mcap_records.hpp"

namespace radargauss {

using namespace mcap;

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
