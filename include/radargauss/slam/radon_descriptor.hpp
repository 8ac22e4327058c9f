// SPDX-License-Identifier: BSD-3-Clause
// A Radon-sinogram descriptor of a keyframe's submap after RING (Lu et al.,
// RSS 2022; docs/design/slam.md, "Place recognition"): the bird's-eye occupancy
// projected on `angles` directions over [0, pi), each projection's DFT
// magnitude without its mean. A translation shifts every projection and leaves the magnitudes
// alone; a yaw shifts the rows circularly, so the best row shift gives the
// yaw, up to pi (a projection and its opposite have the same magnitude).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "radargauss/core/options.hpp"
#include "radargauss/core/types.hpp"
#include "radargauss/slam/place_descriptor.hpp"

namespace radargauss {

struct RadonOptions {
  int angles = 60;          // projection directions over [0, pi)
  int offsets = 64;         // bins of the projection over [-max_range, max_range]
  double cell = 1.0;        // m: the bird's-eye occupancy grid
  double max_range = 80.0;  // m: cells farther are left out
};

// Its options (options.hpp): place recognition's rows radon_*.
const OptionTable<RadonOptions>& RadonOptionTable();
// CheckOptions with that table: throws std::invalid_argument naming the option.
void ValidateRadonOptions(const RadonOptions& options);

struct RadonDescriptor {
  Eigen::MatrixXd
      spectra;  // angles x offsets / 2: |DFT| of each projection (frequencies 1 .. offsets / 2) minus their mean
  Eigen::VectorXd key;  // the rows' mean, unit norm (zero when empty): yaw-invariant
};

// Of points in the keyframe's frame (x forward, z up).
RadonDescriptor MakeRadonDescriptor(const std::vector<RadarPoint>& points, const RadonOptions& options);

struct RadonMatch {
  double distance = 1.0;  // (1 - cosine) / 2 of the aligned spectra: 0 same, 1/2 unrelated, 1 opposite
  int shift = 0;          // query row k matches candidate row k + shift (mod angles)
  double yaw = 0.0;       // rad, [0, pi): the query frame's yaw in the candidate's, or yaw - pi
};

// The best row shift of `query` against `candidate`; distance 1 when either is empty.
RadonMatch CompareRadonDescriptors(const RadonDescriptor& query, const RadonDescriptor& candidate,
                                   const RadonOptions& options);

// The Radon descriptor as a place descriptor: its key, the best row shift's
// yaw and that yaw - pi (a projection is known up to pi).
class RadonPlaceDescriptor final : public PlaceDescriptor {
 public:
  RadonPlaceDescriptor(const RadonOptions& options, double max_distance);
  std::shared_ptr<const PlaceDescription> Describe(const std::vector<RadarPoint>& submap) const override;
  PlaceComparison Compare(const PlaceDescription& query, const PlaceDescription& candidate) const override;
  double MaxDistance() const override { return max_distance_; }

 private:
  RadonOptions options_;
  double max_distance_;
};

}  // namespace radargauss
