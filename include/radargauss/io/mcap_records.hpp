// SPDX-License-Identifier: BSD-3-Clause
// The MCAP records' constants and CRC shared by the reader and the writer
// (io/mcap.hpp; https://mcap.dev/spec). Internal: not installed.
#pragma once

#include <zlib.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace radargauss::mcap {

inline constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
inline constexpr std::uint64_t kRecordHeader = 9;                   // opcode, length
inline constexpr std::uint64_t kFooterRecord = kRecordHeader + 20;  // summary start, summary offset start, CRC

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

inline std::uint32_t Crc(std::uint32_t crc, const std::uint8_t* data, std::size_t size) {
  while (size > 0) {  // zlib's crc32 takes a uInt length
    const std::size_t n = std::min<std::size_t>(size, 1u << 30);
    crc = std::uint32_t(crc32(crc, data, uInt(n)));
    data += n;
    size -= n;
  }
  return crc;
}

}  // namespace radargauss::mcap
