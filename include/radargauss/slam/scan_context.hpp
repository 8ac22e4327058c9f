// SPDX-License-Identifier: BSD-3-Clause
// Scan Context (Kim and Kim, IROS 2018) of a keyframe's submap
// (docs/design/slam.md, "Place recognition"): the bird's-eye view in rings x
// sectors around the keyframe, with a geometric channel (the highest point
// of each bin above the lowest of the submap) and an RCS channel (the
// strongest return of each bin above a floor, radar's counterpart of lidar
// intensity). The ring key (the share of occupied sectors per ring) does not
// change with yaw and finds candidates; the column shift that best aligns
// two descriptors gives their distance and the yaw between them.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "radargauss/core/options.hpp"
#include "radargauss/core/types.hpp"
#include "radargauss/slam/place_descriptor.hpp"

namespace radargauss {

enum class ScanContextChannel { kGeometric, kRcs, kBoth };
std::string ToString(ScanContextChannel channel);                          // "geometric", "rcs", "both"
ScanContextChannel ScanContextChannelFromString(const std::string& name);  // throws std::invalid_argument
std::vector<std::string> ScanContextChannelNames();

struct ScanContextOptions {
  int rings = 20;
  int sectors = 60;
  double max_range = 80.0;   // m: points beyond are left out
  double rcs_floor = -30.0;  // dBsm: the RCS channel holds rcs - floor, at least 0
  ScanContextChannel channel = ScanContextChannel::kBoth;
};

// Its options (options.hpp) but the channel, which is its type's: place
// recognition's rows scan_context_*.
const OptionTable<ScanContextOptions>& ScanContextOptionTable();
// CheckOptions with that table: throws std::invalid_argument naming the option.
void ValidateScanContextOptions(const ScanContextOptions& options);

struct ScanContext {
  Eigen::MatrixXd geometric;  // rings x sectors
  Eigen::MatrixXd rcs;        // rings x sectors
  Eigen::VectorXd ring_key;   // per ring, the share of occupied sectors
};

// Of points in the keyframe's frame (x forward, z up); sector 0 starts at
// azimuth -pi, azimuth grows with the sector.
ScanContext MakeScanContext(const std::vector<RadarPoint>& points, const ScanContextOptions& options);

struct ScanContextMatch {
  double distance = 1.0;  // mean cosine distance of the aligned columns (1 where one is empty), 0 (same) .. 1
  int shift = 0;          // query sector k matches candidate sector k + shift
  double yaw = 0.0;       // rad, (-pi, pi]: the query frame's yaw in the candidate's
};

// The best column shift of `query` against `candidate` in the channels of
// `options`; distance 1 when either is empty.
ScanContextMatch CompareScanContexts(const ScanContext& query, const ScanContext& candidate,
                                     const ScanContextOptions& options);

// Scan Context as a place descriptor: the ring key, the best column shift's yaw.
class ScanContextDescriptor final : public PlaceDescriptor {
 public:
  ScanContextDescriptor(const ScanContextOptions& options, double max_distance);
  std::shared_ptr<const PlaceDescription> Describe(const std::vector<RadarPoint>& submap) const override;
  PlaceComparison Compare(const PlaceDescription& query, const PlaceDescription& candidate) const override;
  double MaxDistance() const override { return max_distance_; }

 private:
  ScanContextOptions options_;
  double max_distance_;
};

}  // namespace radargauss
