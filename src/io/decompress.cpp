// SPDX-License-Identifier: BSD-3-Clause
#include "decompress.hpp"

#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <array>
#include <memory>

#include "radargauss/core/error.hpp"

namespace radargauss {

namespace {

constexpr std::size_t kBlockBytes = std::size_t(1) << 16;
// An lz4 sequence encodes at most 255 bytes of match per byte of input.
constexpr std::uint64_t kLz4MaxRatio = 256;
// zstd's default largest window; a frame asking for more is refused, not allocated.
constexpr int kZstdWindowLogMax = 27;

// Appends what one step produced, refusing output past `bound`.
void Append(std::vector<std::uint8_t>& out, const std::uint8_t* block, std::size_t n, std::uint64_t bound,
            const std::string& path, const std::string& what, bool stated) {
  if (n > bound - out.size()) {
    throw FileError(path, what + " decompresses past " + (stated ? "its stated " : "the limit of ") +
                              std::to_string(bound) + " bytes");
  }
  out.insert(out.end(), block, block + n);
}

std::vector<std::uint8_t> Zstd(const std::uint8_t* data, std::size_t size, std::uint64_t bound, const std::string& path,
                               const std::string& what, bool stated) {
  const std::unique_ptr<ZSTD_DCtx, std::size_t (*)(ZSTD_DCtx*)> context(ZSTD_createDCtx(), ZSTD_freeDCtx);
  if (!context) throw FileError(path, "cannot start zstd decompression");
  ZSTD_DCtx_setParameter(context.get(), ZSTD_d_windowLogMax, kZstdWindowLogMax);
  std::vector<std::uint8_t> out;
  std::array<std::uint8_t, kBlockBytes> block;
  ZSTD_inBuffer in{data, size, 0};
  std::size_t pending = 1;  // 0 once a frame is complete
  for (;;) {
    ZSTD_outBuffer step{block.data(), block.size(), 0};
    pending = ZSTD_decompressStream(context.get(), &step, &in);
    if (ZSTD_isError(pending))
      throw FileError(path, what + " is not a valid zstd frame: " + ZSTD_getErrorName(pending));
    Append(out, block.data(), step.pos, bound, path, what, stated);
    // Done once the input is read and the decoder has nothing more to give.
    if (in.pos == in.size && step.pos < step.size) break;
  }
  if (pending != 0) throw FileError(path, what + " is a zstd frame cut short");
  return out;
}

std::vector<std::uint8_t> Lz4(const std::uint8_t* data, std::size_t size, std::uint64_t bound, const std::string& path,
                              const std::string& what, bool stated) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) {
    throw FileError(path, "cannot start lz4 decompression");
  }
  const std::unique_ptr<LZ4F_dctx, LZ4F_errorCode_t (*)(LZ4F_dctx*)> context(raw, LZ4F_freeDecompressionContext);
  std::vector<std::uint8_t> out;
  std::array<std::uint8_t, kBlockBytes> block;
  std::size_t read = 0, pending = 1;  // 0 once the frame is complete
  for (;;) {
    std::size_t produced = block.size();
    std::size_t consumed = size - read;
    pending = LZ4F_decompress(context.get(), block.data(), &produced, data + read, &consumed, nullptr);
    if (LZ4F_isError(pending)) {
      throw FileError(path, what + " is not a valid lz4 frame: " + LZ4F_getErrorName(pending));
    }
    read += consumed;
    Append(out, block.data(), produced, bound, path, what, stated);
    if (pending == 0 || (read == size && produced == 0)) break;
  }
  if (pending != 0) throw FileError(path, what + " is an lz4 frame cut short");
  if (read != size) throw FileError(path, what + " holds bytes past its lz4 frame");
  return out;
}

}  // namespace

std::vector<std::uint8_t> DecompressFrame(Codec codec, const std::uint8_t* data, std::size_t size,
                                          std::optional<std::uint64_t> stated, std::uint64_t limit,
                                          const std::string& path, const std::string& what) {
  if (stated && *stated > limit) {
    throw FileError(path, what + " of " + std::to_string(*stated) + " bytes uncompressed is past the " +
                              std::to_string(limit >> 20) + " MiB limit");
  }
  if (codec == Codec::kLz4 && stated && *stated / kLz4MaxRatio > size) {
    throw FileError(path, what + " of " + std::to_string(size) + " bytes cannot hold the " + std::to_string(*stated) +
                              " bytes it states (lz4 expands at most " + std::to_string(kLz4MaxRatio) + "-fold)");
  }
  const std::uint64_t bound = stated ? *stated : limit;
  std::vector<std::uint8_t> out = codec == Codec::kZstd ? Zstd(data, size, bound, path, what, stated.has_value())
                                                        : Lz4(data, size, bound, path, what, stated.has_value());
  if (stated && out.size() != *stated) {
    throw FileError(path, what + " decompresses to " + std::to_string(out.size()) + " bytes, not its stated " +
                              std::to_string(*stated));
  }
  return out;
}

}  // namespace radargauss
