// SPDX-License-Identifier: BSD-3-Clause
// One libFuzzer target: RADARGAUSS_FUZZ_TARGET names the entry point
// (fuzz/entry_points.hpp) this binary runs.
#include <cstdlib>
#include <cstring>

#include "entry_points.hpp"

namespace {

radargauss::fuzz::EntryPoint Chosen() {
  for (const radargauss::fuzz::Target& target : radargauss::fuzz::Targets()) {
    if (target.name == RADARGAUSS_FUZZ_TARGET) return target.run;
  }
  std::abort();  // a target CMake names must exist
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const radargauss::fuzz::EntryPoint run = Chosen();
  run(data, size);
  return 0;
}
