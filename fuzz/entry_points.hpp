// SPDX-License-Identifier: BSD-3-Clause
// The inputs radargauss reads, one entry point per format, as the fuzz
// targets (fuzz/target.cpp) and the replay of their findings
// (tests/hostile/test_fuzz_regressions.cpp) call them. Each feeds the bytes to the
// library's real reader; the reader's own errors (DataError, and for the
// CLI's YAML CLI11's ConversionError) are the expected outcome and are
// caught. Anything else escapes: a crash, a leak, UB or a hang is a finding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace radargauss::fuzz {

using EntryPoint = void (*)(const std::uint8_t* data, std::size_t size);

struct Target {
  std::string name;  // also the folder of its corpus and regression inputs
  EntryPoint run;
};

// pcd, kitti_bin, tum, map_file, pointcloud2, simulator_yaml, cli_yaml,
// shard_json, map_places, mcap, cdr, map_tiles, rig_yaml.
const std::vector<Target>& Targets();

}  // namespace radargauss::fuzz
