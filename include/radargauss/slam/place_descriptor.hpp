// SPDX-License-Identifier: BSD-3-Clause
// The place-descriptor interface (docs/design/slam.md, "Place recognition"): a
// descriptor describes a submap, gives its rotation-invariant key, and
// compares two descriptions with the yaw of one in the other. Scan Context
// and Radon stand behind it; PlaceDatabase (place_recognition.hpp) ranks the
// places of SLAM and relocalisation alike through it.
//
//   class MyDescriptor final : public PlaceDescriptor { ... };
//   const bool registered = RegisterPlaceDescriptor("mine", [](const PlaceRecognitionOptions&) {
//     return std::make_unique<MyDescriptor>();
//   });  // then: descriptor "mine" in SlamOptions, --descriptor mine, descriptor="mine"
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "radargauss/core/types.hpp"

namespace radargauss {

// What a descriptor made of a submap: its key, and (in a descriptor's own
// subclass) what it compares in full. A database may keep the key alone.
struct PlaceDescription {
  virtual ~PlaceDescription() = default;
  Eigen::VectorXd key;  // rotation-invariant: nearest keys are compared in full
};

struct PlaceComparison {
  double distance = 1.0;     // 0 (same) .. 1
  std::vector<double> yaws;  // rad: the query frame's yaw in the candidate's, to verify in this order
};

class PlaceDescriptor {
 public:
  virtual ~PlaceDescriptor() = default;
  // Of points in the submap's frame (x forward, z up).
  virtual std::shared_ptr<const PlaceDescription> Describe(const std::vector<RadarPoint>& submap) const = 0;
  // Of two descriptions this descriptor made, whole (not keys alone).
  virtual PlaceComparison Compare(const PlaceDescription& query, const PlaceDescription& candidate) const = 0;
  // Compared places farther than this are not verified.
  virtual double MaxDistance() const = 0;
};

}  // namespace radargauss
