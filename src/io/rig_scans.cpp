// SPDX-License-Identifier: BSD-3-Clause
// A rig's scans in one time order (apart from the rig file's reader, which
// needs no sequence reader).
#include "radargauss/core/error.hpp"
#include "radargauss/io/rig.hpp"

namespace radargauss {

void ForEachRigScan(const Rig& rig,
                    const std::function<void(std::size_t radar, RadarScan& scan, const std::string& source)>& visit) {
  std::vector<Sequence> sequences;
  for (const RigRadar& radar : rig.radars) {
    try {
      sequences.push_back(LoadSequence(radar.scans));
    } catch (const DataError& e) {
      throw DataError("radar '" + radar.name + "': " + e.what());
    }
    for (RadarScan& scan : sequences.back().scans) scan.timestamp -= radar.clock_offset;
  }
  std::vector<std::size_t> next(sequences.size(), 0);
  while (true) {
    std::size_t radar = sequences.size();
    for (std::size_t r = 0; r < sequences.size(); ++r) {
      if (next[r] == sequences[r].scans.size()) continue;
      if (radar == sequences.size() ||
          sequences[r].scans[next[r]].timestamp < sequences[radar].scans[next[radar]].timestamp) {
        radar = r;
      }
    }
    if (radar == sequences.size()) return;
    const std::size_t k = next[radar]++;
    visit(radar, sequences[radar].scans[k], sequences[radar].scan_sources[k]);
  }
}

}  // namespace radargauss
