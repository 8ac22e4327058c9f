// SPDX-License-Identifier: BSD-3-Clause
// A rig's scans in one time order (apart from the rig file's reader, which
// needs no sequence reader).
#include "radargauss/core/error.hpp"
#include "radargauss/io/rig.hpp"

#include <utility>

namespace radargauss {

std::vector<Sequence> LoadRigSequences(const Rig& rig) {
  std::vector<Sequence> sequences;
  for (const RigRadar& radar : rig.radars) {
    try {
      sequences.push_back(LoadSequence(radar.scans));
    } catch (const DataError& e) {
      throw DataError("radar '" + radar.name + "': " + e.what());
    }
  }
  return sequences;
}

std::vector<std::vector<RadarScan>> LoadRigScans(const Rig& rig) {
  std::vector<std::vector<RadarScan>> scans;
  for (Sequence& sequence : LoadRigSequences(rig)) scans.push_back(std::move(sequence.scans));
  return scans;
}

void ForEachRigScan(const Rig& rig,
                    const std::function<void(std::size_t radar, RadarScan& scan, const std::string& source)>& visit) {
  std::vector<Sequence> sequences = LoadRigSequences(rig);
  for (std::size_t r = 0; r < sequences.size(); ++r) {
    for (RadarScan& scan : sequences[r].scans) scan.timestamp -= rig.radars[r].clock_offset;
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
