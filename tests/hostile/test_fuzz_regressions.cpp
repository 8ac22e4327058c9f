// SPDX-License-Identifier: BSD-3-Clause
// Every input under tests/data/fuzz/<target>/ (inputs that crashed, hung or
// ran into UB before the fixes, fuzz/README.md) goes through the entry
// point of its fuzz target: only the library's own errors may come out.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "../fuzz/entry_points.hpp"

namespace radargauss {
namespace {

namespace fs = std::filesystem;

TEST(FuzzRegressions, EveryInputGivesTheLibrarysOwnError) {
  const fs::path root = fs::path(RADARGAUSS_SOURCE_DIR) / "tests" / "data" / "fuzz";
  std::size_t replayed = 0;
  for (const fuzz::Target& target : fuzz::Targets()) {
    if (!fs::is_directory(root / target.name)) continue;
    for (const auto& entry : fs::directory_iterator(root / target.name)) {
      std::ifstream in(entry.path(), std::ios::binary);
      const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      SCOPED_TRACE(entry.path().string());
      EXPECT_NO_THROW(target.run(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()));
      ++replayed;
    }
  }
  EXPECT_GE(replayed, 8u) << "the regression inputs are missing";
}

}  // namespace
}  // namespace radargauss
