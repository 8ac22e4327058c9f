// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/slam/place_recognition.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <map>
#include <unordered_set>
#include <utility>

#include "radargauss/core/names.hpp"
#include "radargauss/core/voxel_grid.hpp"

namespace radargauss {

namespace {

// The built-in descriptors are registered here, where the registry starts:
// a static library's file that only registers would not be linked.
std::map<std::string, PlaceDescriptorFactory>& Registry() {
  static std::map<std::string, PlaceDescriptorFactory> registry = {
      {"scan-context",
       [](const PlaceRecognitionOptions& o) {
         return std::make_unique<ScanContextDescriptor>(o.scan_context, o.max_scan_context_distance);
       }},
      {"radon",
       [](const PlaceRecognitionOptions& o) {
         return std::make_unique<RadonPlaceDescriptor>(o.radon, o.max_radon_distance);
       }},
  };
  return registry;
}

}  // namespace

bool RegisterPlaceDescriptor(const std::string& name, PlaceDescriptorFactory factory) {
  if (name.empty() || !factory) throw std::invalid_argument("a place descriptor needs a name and a factory");
  if (!Registry().emplace(name, std::move(factory)).second) {
    throw std::invalid_argument("place descriptor '" + name + "' is registered already");
  }
  return true;
}

std::vector<std::string> PlaceDescriptorNames() {
  std::vector<std::string> names = {"scan-context", "radon"};  // the built-ins first, as the docs list them
  for (const auto& entry : Registry()) {
    if (entry.first != "scan-context" && entry.first != "radon") names.push_back(entry.first);
  }
  return names;
}

std::unique_ptr<PlaceDescriptor> MakePlaceDescriptor(const PlaceRecognitionOptions& options) {
  const auto found = Registry().find(options.descriptor);
  if (found == Registry().end()) {
    throw std::invalid_argument("unknown place descriptor '" + options.descriptor + "' (" +
                                Joined(PlaceDescriptorNames()) + ")");
  }
  std::unique_ptr<PlaceDescriptor> descriptor = found->second(options);
  if (!descriptor) throw std::invalid_argument("place descriptor '" + options.descriptor + "' made nothing");
  return descriptor;
}

const OptionTable<PlaceRecognitionOptions>& PlaceRecognitionOptionTable() {
  using O = PlaceRecognitionOptions;
  static const OptionTable<O> table = [] {
    OptionTable<O> t = {
        RADARGAUSS_OPTION(O, "descriptor", descriptor)
            .Choices(PlaceDescriptorNames())
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
    };
    // The descriptors' own rows, as scan_context_* and radon_*.
    AppendNested(
        t, ScanContextOptionTable(), +[](O & o) -> auto& { return o.scan_context; }, "scan_context", "scan_context_");
    AppendNested(
        t, RadonOptionTable(), +[](O & o) -> auto& { return o.radon; }, "radon", "radon_");
    return t;
  }();
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

PlaceDatabase::PlaceDatabase(const PlaceRecognitionOptions& options, Redescribe describe)
    : descriptor_(MakePlaceDescriptor(options)), candidates_(options.candidates), describe_(std::move(describe)) {
  ValidateOptions(options);
}

void PlaceDatabase::Add(std::shared_ptr<const PlaceDescription> description) {
  if (!description) throw std::invalid_argument("PlaceDatabase::Add: no description");
  if (describe_) {  // the key alone
    auto key = std::make_shared<PlaceDescription>();
    key->key = description->key;
    description = std::move(key);
  }
  places_.push_back(std::move(description));
}

std::vector<PlaceMatch> PlaceDatabase::Rank(const PlaceDescription& query, const std::vector<int>& eligible) const {
  std::vector<std::pair<double, int>> nearest;
  for (const int c : eligible) nearest.emplace_back((query.key - places_.at(std::size_t(c))->key).norm(), c);
  const std::size_t kept = std::min<std::size_t>(nearest.size(), std::size_t(candidates_));
  std::partial_sort(nearest.begin(), nearest.begin() + kept, nearest.end());
  nearest.resize(kept);
  std::vector<PlaceMatch> matches;
  for (const auto& [key_distance, c] : nearest) {
    const std::shared_ptr<const PlaceDescription> candidate = describe_ ? describe_(c) : places_[std::size_t(c)];
    const PlaceComparison comparison = descriptor_->Compare(query, *candidate);
    PlaceMatch match;
    match.candidate = c;
    match.distance = comparison.distance;
    match.yaws = comparison.yaws.empty() ? std::vector<double>{0.0} : comparison.yaws;  // no yaw known: 0
    match.close = comparison.distance <= descriptor_->MaxDistance();
    matches.push_back(std::move(match));
  }
  std::stable_sort(matches.begin(), matches.end(),
                   [](const PlaceMatch& a, const PlaceMatch& b) { return a.distance < b.distance; });
  return matches;
}

}  // namespace radargauss
