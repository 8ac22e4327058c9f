// SPDX-License-Identifier: BSD-3-Clause
// Place recognition over submaps (docs/design/slam.md, "Place recognition"): the
// selected descriptor (place_descriptor.hpp) describes a submap; a
// PlaceDatabase holds the places, ranks the candidates nearest a query by
// key and compares them in full, which gives a distance and the yaws to
// verify. SLAM searches its own keyframes with it, relocalisation a map's places.
//
//   PlaceDatabase places(options);
//   places.Add(places.Describe(submap));
//   for (const PlaceMatch& match : places.Rank(*places.Describe(query), eligible)) ...
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "radargauss/core/options.hpp"
#include "radargauss/slam/place_descriptor.hpp"
#include "radargauss/slam/radon_descriptor.hpp"
#include "radargauss/slam/scan_context.hpp"
#include "radargauss/core/types.hpp"

namespace radargauss {

struct PlaceRecognitionOptions {
  std::string descriptor = "scan-context";  // a name of PlaceDescriptorNames()
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

// The descriptors by name: "scan-context" and "radon", and any registered.
using PlaceDescriptorFactory = std::function<std::unique_ptr<PlaceDescriptor>(const PlaceRecognitionOptions&)>;
// Adds `factory` under `name`; throws std::invalid_argument for a name taken.
// Returns true, so that a file can register one at its static initialisation.
bool RegisterPlaceDescriptor(const std::string& name, PlaceDescriptorFactory factory);
std::vector<std::string> PlaceDescriptorNames();
// Throws std::invalid_argument for an unknown name.
std::unique_ptr<PlaceDescriptor> MakePlaceDescriptor(const PlaceRecognitionOptions& options);

// Its options (options.hpp); ValidateOptions throws std::invalid_argument naming the bad one.
const OptionTable<PlaceRecognitionOptions>& PlaceRecognitionOptionTable();
void ValidateOptions(const PlaceRecognitionOptions& options);

// The first point of each voxel of edge `voxel`, in arrival order.
std::vector<RadarPoint> DownsampleSubmap(const std::vector<RadarPoint>& points, double voxel);

struct PlaceMatch {
  int candidate = 0;
  double distance = 1.0;     // the descriptor's, 0 (same) .. 1
  std::vector<double> yaws;  // rad, the query's in the candidate's, to verify in order (Radon: yaw and yaw - pi)
  bool close = false;        // distance within the descriptor's maximum
};

// The places a search ranks, by one descriptor: each whole, or its key alone
// (a few hundred bytes a place, not the descriptor's kilobytes) with
// `describe(place)` to make it whole again when it is compared.
class PlaceDatabase {
 public:
  using Redescribe = std::function<std::shared_ptr<const PlaceDescription>(int place)>;
  explicit PlaceDatabase(const PlaceRecognitionOptions& options, Redescribe describe = nullptr);

  std::shared_ptr<const PlaceDescription> Describe(const std::vector<RadarPoint>& submap) const {
    return descriptor_->Describe(submap);
  }
  // Adds the next place (index size()).
  void Add(std::shared_ptr<const PlaceDescription> description);
  // The `candidates` places nearest `query` by key among `eligible`,
  // compared in full, nearest first.
  std::vector<PlaceMatch> Rank(const PlaceDescription& query, const std::vector<int>& eligible) const;
  std::size_t size() const { return places_.size(); }
  // A place as kept: whole, or its key alone when the database re-describes.
  const PlaceDescription& place(std::size_t index) const { return *places_.at(index); }
  const PlaceDescriptor& descriptor() const { return *descriptor_; }

 private:
  std::unique_ptr<PlaceDescriptor> descriptor_;
  int candidates_;
  Redescribe describe_;
  std::vector<std::shared_ptr<const PlaceDescription>> places_;
};

}  // namespace radargauss
