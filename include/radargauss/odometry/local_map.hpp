// SPDX-License-Identifier: BSD-3-Clause
// Odometry's map, built as the radar moves (docs/design.md, "Odometry"):
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
#include <vector>

#include <Eigen/Core>

#include "radargauss/lie/se3.hpp"
#include "radargauss/map/builder.hpp"
#include "radargauss/map/gaussian_map.hpp"
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

struct LocalMapOptions {
  double region = 4.0;                // m: edge of the cubes whose points are fitted together
  std::size_t region_capacity = 256;  // points a region keeps (the newest)
  std::size_t min_points = 8;         // points a region needs for its first fit
  double refit_growth = 0.5;          // refit once the points added since the last fit reach this share of those fitted
  double active_radius = 100.0;       // m: regions whose centre is farther from the radar leave
  // The radar's angular noise: a Gaussian is at least this angle times the
  // mean range its members were seen at wide, horizontally (azimuth) and
  // vertically (elevation), and at least min_std, so that far, sparse
  // returns still gate into the map (docs/design.md, "Odometry").
  double azimuth_std_deg = 0.0;
  double elevation_std_deg = 0.0;
  GaussianMapOptions gaussians;       // the estimator of build-map
  RcsFitOptions rcs;                  // incidence model and SH degree of the RCS models
  MatchingMapOptions matching = LocalMatchingMapOptions();  // coarse levels, index cells (always updatable)
};

// Throws std::invalid_argument naming the bad option.
void ValidateOptions(const LocalMapOptions& options);

class LocalMap {
 public:
  explicit LocalMap(const LocalMapOptions& options = {});

  // Adds `points` (world frame; rcs[i] in dBsm, or `rcs` empty when the scan
  // has none) seen from `pose` (T_world_radar), then refits the regions that
  // gained enough. Returns the number of regions refitted.
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
  // The Gaussians that left the active map, then the active ones.
  GaussianMap GlobalMap() const;
  std::size_t global_gaussians() const { return evicted_.size() + gaussians(); }
  // Points, Gaussians and indexes held (bytes, approximate).
  std::size_t MemoryBytes() const;

 private:
  struct Region {
    std::vector<Eigen::Vector3d> points;  // world frame, at most region_capacity (a ring once full)
    std::vector<double> rcs;
    std::vector<std::uint32_t> pose;      // into poses_
    std::size_t next = 0;                 // the ring's oldest point once full
    std::size_t fitted = 0;               // points at the last fit
    std::size_t added = 0;                // points since the last fit
    std::vector<std::uint32_t> gaussians; // their slots in map_
    bool has_rcs = false;
  };
  // Fits the Gaussians of `region` again; their slots go to changed/removed.
  void Refit(Region& region, std::vector<std::uint32_t>& changed, std::vector<std::uint32_t>& removed);
  // Widens each fitted Gaussian to the angular noise at its members' mean
  // range from the poses they were seen from.
  void FloorAtRange(const Region& region, const std::vector<int>& association, GaussianMap& fitted) const;
  std::uint32_t NewSlot();

  LocalMapOptions options_;
  std::shared_ptr<GaussianMap> map_;        // slots; free ones are in no index
  std::unique_ptr<MatchingMap> matching_;   // over map_
  std::vector<std::uint32_t> free_slots_;
  std::map<VoxelKey, Region> regions_;
  std::vector<SE3d> poses_;                 // the poses points were inserted from
  std::vector<Gaussian> evicted_;           // the global map's Gaussians that left
  std::size_t version_ = 0;
};

}  // namespace radargauss
