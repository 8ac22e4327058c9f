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

void ValidateOptions(const PlaceRecognitionOptions& o) {
  ValidateScanContextOptions(o.scan_context);
  ValidateRadonOptions(o.radon);
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("place recognition: ") + what);
  };
  require(o.submap_voxel > 0.0 && std::isfinite(o.submap_voxel), "submap_voxel must be positive");
  require(o.candidates >= 1, "candidates must be >= 1");
  require(o.max_scan_context_distance >= 0.0 && o.max_scan_context_distance <= 1.0 && o.max_radon_distance >= 0.0 &&
              o.max_radon_distance <= 1.0,
          "the maximum descriptor distances must be in [0, 1]");
}

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
