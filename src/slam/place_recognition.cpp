// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/slam/place_recognition.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_set>

#include "radargauss/names.hpp"
#include "radargauss/voxel_grid.hpp"

namespace radargauss {

namespace {

constexpr NamedValue<PlaceDescriptorKind> kDescriptorNames[] = {{PlaceDescriptorKind::kScanContext, "scan-context"},
                                                                {PlaceDescriptorKind::kRadon, "radon"}};

}  // namespace

std::string ToString(PlaceDescriptorKind kind) { return NameOf(kDescriptorNames, kind); }
PlaceDescriptorKind PlaceDescriptorKindFromString(const std::string& name) {
  return ValueNamed(kDescriptorNames, name, "place descriptor");
}
std::vector<std::string> PlaceDescriptorKindNames() { return NamesOf(kDescriptorNames); }

const OptionTable<PlaceRecognitionOptions>& PlaceRecognitionOptionTable() {
  using O = PlaceRecognitionOptions;
  static const OptionTable<O> table = {
      RADARGAUSS_CHOICE(O, "descriptor", descriptor, PlaceDescriptorKindNames(), PlaceDescriptorKindFromString)
          .Sensor()
          .Help("place descriptor: scan-context or radon"),
      RADARGAUSS_OPTION(O, "candidates", candidates).In(1, 100000).Help("places compared per submap (nearest keys)"),
      RADARGAUSS_OPTION(O, "max_scan_context_distance", max_scan_context_distance)
          .In(0.0, 1.0)
          .Help("places farther by Scan Context are not verified"),
      RADARGAUSS_OPTION(O, "max_radon_distance", max_radon_distance)
          .In(0.0, 1.0)
          .Help("places farther by the Radon descriptor are not verified"),
      RADARGAUSS_OPTION(O, "submap_voxel", submap_voxel)
          .Above(0.0)
          .Unit("m")
          .Help("a submap keeps the first point of each voxel of this edge"),
      RADARGAUSS_CHOICE(O, "channel", scan_context.channel, ScanContextChannelNames(), ScanContextChannelFromString)
          .Help("Scan Context channels: geometric, rcs or both"),
      RADARGAUSS_OPTION(O, "scan_context_rings", scan_context.rings).In(1, 1000).Help("Scan Context: rings"),
      RADARGAUSS_OPTION(O, "scan_context_sectors", scan_context.sectors).In(1, 1000).Help("Scan Context: sectors"),
      RADARGAUSS_OPTION(O, "scan_context_max_range", scan_context.max_range)
          .Above(0.0)
          .Unit("m")
          .Help("Scan Context: points beyond are left out"),
      RADARGAUSS_OPTION(O, "scan_context_rcs_floor", scan_context.rcs_floor)
          .Unit("dBsm")
          .Help("Scan Context: the RCS channel holds rcs - floor, at least 0"),
      RADARGAUSS_OPTION(O, "radon_angles", radon.angles).In(2, 1000).Help("Radon: projection directions over [0, pi)"),
      RADARGAUSS_OPTION(O, "radon_offsets", radon.offsets).In(2, 1000).Help("Radon: bins of a projection"),
      RADARGAUSS_OPTION(O, "radon_cell", radon.cell).Above(0.0).Unit("m").Help("Radon: the bird's-eye grid's cell"),
      RADARGAUSS_OPTION(O, "radon_max_range", radon.max_range)
          .Above(0.0)
          .Unit("m")
          .Help("Radon: cells farther are left out"),
  };
  return table;
}

void ValidateOptions(const PlaceRecognitionOptions& o) { CheckOptions(PlaceRecognitionOptionTable(), o); }

std::vector<RadarPoint> DownsampleSubmap(const std::vector<RadarPoint>& points, double voxel) {
  std::unordered_set<std::int64_t> seen;
  std::vector<RadarPoint> kept;
  for (const RadarPoint& point : points) {
    if (seen.insert(PackVoxelKey(VoxelOf(point.position, voxel))).second) kept.push_back(point);
  }
  return kept;
}

PlaceDescription Describe(const std::vector<RadarPoint>& submap, const PlaceRecognitionOptions& options) {
  PlaceDescription description;
  if (options.descriptor == PlaceDescriptorKind::kScanContext) {
    description.scan_context = MakeScanContext(submap, options.scan_context);
  } else {
    description.radon = MakeRadonDescriptor(submap, options.radon);
  }
  return description;
}

const Eigen::VectorXd& KeyOf(const PlaceDescription& description, const PlaceRecognitionOptions& options) {
  return options.descriptor == PlaceDescriptorKind::kScanContext ? description.scan_context.ring_key
                                                                 : description.radon.key;
}

std::vector<PlaceMatch> RankPlaces(const PlaceDescription& query, const std::vector<PlaceDescription>& places,
                                   const std::vector<int>& eligible, const PlaceRecognitionOptions& options) {
  return RankPlaces(query, places, eligible, options, nullptr);
}

std::vector<PlaceMatch> RankPlaces(const PlaceDescription& query, const std::vector<PlaceDescription>& keys,
                                   const std::vector<int>& eligible, const PlaceRecognitionOptions& options,
                                   const std::function<PlaceDescription(int)>& describe) {
  const Eigen::VectorXd& query_key = KeyOf(query, options);
  std::vector<std::pair<double, int>> nearest;
  for (const int c : eligible) nearest.emplace_back((query_key - KeyOf(keys[c], options)).norm(), c);
  const std::size_t kept = std::min<std::size_t>(nearest.size(), std::size_t(options.candidates));
  std::partial_sort(nearest.begin(), nearest.begin() + kept, nearest.end());
  nearest.resize(kept);
  std::vector<PlaceMatch> matches;
  PlaceDescription described;
  for (const auto& [key_distance, c] : nearest) {
    if (describe) described = describe(c);
    const PlaceDescription& candidate = describe ? described : keys[c];
    PlaceMatch match;
    match.candidate = c;
    if (options.descriptor == PlaceDescriptorKind::kScanContext) {
      const ScanContextMatch m = CompareScanContexts(query.scan_context, candidate.scan_context, options.scan_context);
      match.distance = m.distance;
      match.yaws = {m.yaw};
      match.close = m.distance <= options.max_scan_context_distance;
    } else {
      const RadonMatch m = CompareRadonDescriptors(query.radon, candidate.radon, options.radon);
      match.distance = m.distance;
      match.yaws = {m.yaw, m.yaw - M_PI};  // known up to pi
      match.close = m.distance <= options.max_radon_distance;
    }
    matches.push_back(std::move(match));
  }
  std::stable_sort(matches.begin(), matches.end(),
                   [](const PlaceMatch& a, const PlaceMatch& b) { return a.distance < b.distance; });
  return matches;
}

PlaceDescription KeyOnly(PlaceDescription description) {
  description.scan_context.geometric.resize(0, 0);
  description.scan_context.rcs.resize(0, 0);
  description.radon.spectra.resize(0, 0);
  return description;
}

}  // namespace radargauss
