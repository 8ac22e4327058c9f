// SPDX-License-Identifier: BSD-3-Clause
// Odometry's map, built as the radar moves (docs/design/odometry.md, "Odometry"):
// static points at their estimated poses in a hash of regions (cubes of
// `region` metres). A region that has gained enough points since its last
// fit gets its Gaussians fitted again from its points with the estimator of
// build-map (k-means + hard EM, the same minimum std) and their RCS models
// refitted from their members and the poses they were seen from. Only the
// regions within `active_radius` of the radar stay; the others leave their
// Gaussians to the global map and drop their points, so time and memory per
// scan stay flat. The MatchingMap follows every change (MatchingMap::Update).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "radargauss/lie/se3.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/map/gaussian_statistics.hpp"
#include "radargauss/map/rcs_model.hpp"
#include "radargauss/map/matching_map.hpp"

namespace radargauss {

// The local map's matching levels: the prediction starts a match within
// centimetres, so one coarse level of 0.25 m suffices (three cost 2.5x the
// map update and gained nothing, bench/RESULTS.md, "Odometry"), and 1 m index
// cells let an update touch 8x fewer cells than 0.5 m for the same answers.
inline MatchingMapOptions LocalMatchingMapOptions() {
  MatchingMapOptions options;
  options.inflation = {0.25};
  options.index_cell = 1.0;
  return options;
}

// How a region's Gaussians follow its points (docs/design/odometry.md, "The
// incremental map"): kRefit fits them again from all its points with
// build-map's estimator once enough have come; kIncremental updates each
// Gaussian's sufficient statistics point by point and publishes a Gaussian
// to the matching map once it has moved by `republish_kl` since it last was.
enum class MapEstimator : std::uint8_t { kRefit, kIncremental };
std::string ToString(MapEstimator estimator);
MapEstimator MapEstimatorFromString(const std::string& name);  // "refit", "incremental"; throws std::invalid_argument
std::vector<std::string> MapEstimatorNames();

// The largest angular noise a map floor takes (deg). Real 4D radars have
// 0.1-2 deg in azimuth and up to a few in elevation; a floor of tens of
// degrees makes Gaussians tens of metres wide at range, each listed in
// 10^5 index cells (10 deg: 7.6 s and 430 MB for 40 scans; 20 deg: 86 s, 3.4 GB).
inline constexpr double kMaxAngularNoiseDeg = 5.0;

struct LocalMapOptions {
  MapEstimator estimator = MapEstimator::kRefit;
  double region = 4.0;                // m: edge of the cubes whose points are fitted together
  std::size_t region_capacity = 256;  // points a region keeps (the newest)
  std::size_t min_points = 8;         // points a region needs for its first fit
  double refit_growth = 0.5;          // refit once the points added since the last fit reach this share of those fitted
  double active_radius = 100.0;       // m: regions whose centre is farther from the radar leave
  // Whether the Gaussians that leave stay for the odometry's global map
  // (GlobalMap, odometry's map.rgm); false: memory bounded by the active
  // radius, not the drive, and no global map beyond the active one.
  bool keep_evicted = true;
  double republish_kl = 2.0;  // nats: KL(updated || published) that republishes a Gaussian (kIncremental)
  // The radar's angular noise: a Gaussian is at least this angle times the
  // mean range its members were seen at wide, horizontally (azimuth) and
  // vertically (elevation), and at least min_std, so that far, sparse
  // returns still gate into the map (docs/design/odometry.md, "Odometry").
  double azimuth_std_deg = 0.0;  // in [0, kMaxAngularNoiseDeg]
  double elevation_std_deg = 0.0;
  GaussianMapOptions gaussians;                             // the estimator of build-map
  RcsFitOptions rcs;                                        // incidence model and SH degree of the RCS models
  MatchingMapOptions matching = LocalMatchingMapOptions();  // coarse levels, index cells (always updatable)
};

// Its options (options.hpp); ValidateOptions throws std::invalid_argument naming the bad one.
const OptionTable<LocalMapOptions>& LocalMapOptionTable();
void ValidateOptions(const LocalMapOptions& options);

// `covariance` widened to the radar's angular noise at `range` (m) and at
// least min_std: Sigma' = F clamp(F^-1 Sigma F^-1, 1) F (docs/design/odometry.md,
// "Odometry").
Eigen::Matrix3d FlooredAtRange(const Eigen::Matrix3d& covariance, double range, const LocalMapOptions& options);

class LocalMap {
 public:
  explicit LocalMap(const LocalMapOptions& options = {});

  // Adds `points` (world frame; rcs[i] in dBsm, or `rcs` empty when the scan
  // has none) seen from `pose` (T_world_radar), then refits the regions that
  // gained enough (kIncremental: updates the regions' Gaussians). Returns the
  // number of regions whose Gaussians changed in the matching map.
  std::size_t Insert(const std::vector<Eigen::Vector3d>& points, const std::vector<double>& rcs, const SE3d& pose);
  // Hands the regions whose centre lies beyond the active radius of
  // `position` to the global map. Returns how many left.
  std::size_t Evict(const Eigen::Vector3d& position);

  const MatchingMap& matching() const { return *matching_; }
  std::size_t gaussians() const { return matching_->indexed(); }  // in the active map
  std::size_t regions() const { return regions_.size(); }
  std::size_t points() const;
  // The active regions' points (world frame), in region order.
  std::vector<Eigen::Vector3d> ActivePoints() const;
  // Changes with every Insert or Evict that changed the map.
  std::size_t version() const { return version_; }
  // The Gaussians that left the active map (keep_evicted), then the active ones.
  GaussianMap GlobalMap() const;
  std::size_t global_gaussians() const { return evicted_.size() + gaussians(); }
  // Points, Gaussians and indexes held (bytes, approximate).
  std::size_t MemoryBytes() const;

 private:
  static constexpr std::uint32_t kNoSlot = 0xffffffffu;
  // One Gaussian of an incremental region: its members' statistics and what
  // the matching map has of it.
  struct Component {
    PointStatistics points;
    double range_sum = 0.0;                                 // members' ranges from the poses they were seen from
    std::unique_ptr<RcsStatistics> rcs;                     // when the region has RCS
    std::uint32_t slot = kNoSlot;                           // in map_, once published
    Eigen::Matrix3d information = Eigen::Matrix3d::Zero();  // the published covariance's inverse
    std::uint32_t changes = 0;                              // members that came or left since the last KL check
    bool reshaped = false;                                  // seeded or split: publish whatever the KL
  };
  struct Region {
    std::vector<Eigen::Vector3d> points;  // world frame, at most region_capacity (a ring once full)
    std::vector<double> rcs;
    std::vector<std::uint32_t> pose;       // into poses_
    std::size_t next = 0;                  // the ring's oldest point once full
    std::size_t fitted = 0;                // points at the last fit
    std::size_t added = 0;                 // points since the last fit
    std::vector<std::uint32_t> gaussians;  // their slots in map_
    bool has_rcs = false;
    // kIncremental: each point's component (-1: pending, in no Gaussian's
    // gate yet) and incidence direction, the components, and the points per
    // voxel of build-map's downsampling (the number of Gaussians it would fit).
    std::vector<std::int32_t> member;
    std::vector<Eigen::Vector3d> direction;
    std::vector<Component> components;
    std::size_t pending = 0;
    std::size_t pending_at_seeding = 0;
    std::unordered_map<std::int64_t, std::uint32_t> voxels;
  };
  // The Gaussians of `region` fitted again from its points (build-map's
  // estimator, floored at range, their RCS models).
  GaussianMap Fit(const Region& region) const;
  // `fitted` in place of the region's Gaussians; their slots go to changed/removed.
  void Replace(Region& region, GaussianMap fitted, std::vector<std::uint32_t>& changed,
               std::vector<std::uint32_t>& removed);
  // Widens each fitted Gaussian to the angular noise at its members' mean
  // range from the poses they were seen from.
  void FloorAtRange(const Region& region, const std::vector<int>& association, GaussianMap& fitted) const;
  std::uint32_t NewSlot();
  void FreeSlot(std::uint32_t slot, std::vector<std::uint32_t>& removed);

  // kIncremental (src/odometry/local_map_incremental.cpp).
  // Places point `i` of the region, just written, in the nearest component
  // whose gate holds it, or leaves it pending.
  void Assign(Region& region, std::size_t i);
  // Takes point `i`, about to be overwritten, out of its component.
  void Forget(Region& region, std::size_t i);
  void Join(Region& region, std::size_t i, std::int32_t component);
  // Seeds components from the pending points, merges or splits them to
  // build-map's count, drops the empty ones and publishes those that moved.
  void Maintain(Region& region, std::vector<std::uint32_t>& changed, std::vector<std::uint32_t>& removed);
  void Seed(Region& region);
  void Merge(Region& region, std::size_t target);
  void Split(Region& region, std::size_t target);
  void Publish(Region& region, std::vector<std::uint32_t>& changed, std::vector<std::uint32_t>& removed);
  // Frees the slots of the components left without members and renumbers the rest.
  void Retire(Region& region, std::vector<std::uint32_t>& removed);
  // Restarts a component's statistics from its members.
  void Recompute(Region& region, std::int32_t component);

  LocalMapOptions options_;
  std::shared_ptr<GaussianMap> map_;       // slots; free ones are in no index
  std::unique_ptr<MatchingMap> matching_;  // over map_
  std::vector<std::uint32_t> free_slots_;
  std::map<VoxelKey, Region> regions_;
  std::vector<SE3d> poses_;        // the poses points were inserted from
  std::vector<Gaussian> evicted_;  // the global map's Gaussians that left
  std::size_t version_ = 0;
};

}  // namespace radargauss
