// SPDX-License-Identifier: BSD-3-Clause
// zstd and lz4 frames undone as a stream: the output grows only as the data
// produces it, so a container that states a size the data does not hold
// costs no more memory than the data itself (docs/design/formats.md, "Bounds on input").
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace radargauss {

enum class Codec { kZstd, kLz4 };

// The `size` bytes at `data` decompressed. `stated`: the size the container
// gives (the output must be exactly that), or nullopt when it gives none
// (the output may be up to `limit`). Throws DataError "<path>: <what> ..."
// when the data is not a frame of `codec`, is cut short, or produces more or
// less than stated; an lz4 frame stating more than lz4 can expand to is
// refused before anything is decompressed.
std::vector<std::uint8_t> DecompressFrame(Codec codec, const std::uint8_t* data, std::size_t size,
                                          std::optional<std::uint64_t> stated, std::uint64_t limit,
                                          const std::string& path, const std::string& what);

}  // namespace radargauss
