// SPDX-License-Identifier: BSD-3-Clause
// Place recognition over submaps (docs/design.md, "Place recognition"): a
// submap's description by the selected descriptor, the candidates nearest by
// its yaw-invariant key, and the full comparison that gives a distance and
// the yaws to verify. SLAM searches its own keyframes with it,
// relocalisation a map's places.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/options.hpp"
#include "radargauss/slam/radon_descriptor.hpp"
#include "radargauss/slam/scan_context.hpp"
#include "radargauss/types.hpp"

namespace radargauss {

enum class PlaceDescriptorKind { kScanContext, kRadon };
std::string ToString(PlaceDescriptorKind kind);                              // "scan-context", "radon"
PlaceDescriptorKind PlaceDescriptorKindFromString(const std::string& name);  // throws std::invalid_argument
std::vector<std::string> PlaceDescriptorKindNames();

struct PlaceRecognitionOptions {
  PlaceDescriptorKind descriptor = PlaceDescriptorKind::kScanContext;
  ScanContextOptions scan_context;
  RadonOptions radon;
  double submap_voxel = 0.25;  // m: a submap keeps the first point of each voxel
  // Compared per query, nearest by key. On the two-lap drive (Radon) 10
  // closed 71 % of the true revisits, 20 81 %, 30 84 %, none false, at
  // 35 / 39 / 41 ms per keyframe: only close candidates are verified.
  int candidates = 20;
  // Compared places farther than this (the descriptor's distance) are not verified.
  double max_scan_context_distance = 0.4;
  double max_radon_distance = 0.15;
};

// Its options (options.hpp); ValidateOptions throws std::invalid_argument naming the bad one.
const OptionTable<PlaceRecognitionOptions>& PlaceRecognitionOptionTable();
void ValidateOptions(const PlaceRecognitionOptions& options);

// The first point of each voxel of edge `voxel`, in arrival order.
std::vector<RadarPoint> DownsampleSubmap(const std::vector<RadarPoint>& points, double voxel);

// The selected descriptor of a submap (the other is left empty).
struct PlaceDescription {
  ScanContext scan_context;
  RadonDescriptor radon;
};
PlaceDescription Describe(const std::vector<RadarPoint>& submap, const PlaceRecognitionOptions& options);
// The yaw-invariant key: Scan Context's ring key or the Radon key.
const Eigen::VectorXd& KeyOf(const PlaceDescription& description, const PlaceRecognitionOptions& options);

struct PlaceMatch {
  int candidate = 0;
  double distance = 1.0;     // the descriptor's, 0 (same) .. 1
  std::vector<double> yaws;  // rad, the query's in the candidate's, to verify in order (Radon: yaw and yaw - pi)
  bool close = false;        // distance within the descriptor's maximum
};

// The `candidates` descriptions nearest `query` by key among the `eligible`
// indices of `places`, compared in full, nearest first.
std::vector<PlaceMatch> RankPlaces(const PlaceDescription& query, const std::vector<PlaceDescription>& places,
                                   const std::vector<int>& eligible, const PlaceRecognitionOptions& options);
// The same for a database that keeps only the keys of its places (a few
// hundred bytes a place, not the descriptor's kilobytes): the compared
// candidates' full descriptions are made by describe(index).
std::vector<PlaceMatch> RankPlaces(const PlaceDescription& query, const std::vector<PlaceDescription>& keys,
                                   const std::vector<int>& eligible, const PlaceRecognitionOptions& options,
                                   const std::function<PlaceDescription(int)>& describe);
// The description with its key alone (what the second RankPlaces needs of a place).
PlaceDescription KeyOnly(PlaceDescription description);

}  // namespace radargauss
