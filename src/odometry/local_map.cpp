// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/odometry/local_map.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include <tbb/parallel_for.h>

#include "radargauss/map/map_cloud.hpp"
#include "radargauss/core/names.hpp"

namespace radargauss {

namespace {

const NamedValue<MapEstimator> kEstimatorNames[] = {{MapEstimator::kRefit, "refit"},
                                                    {MapEstimator::kIncremental, "incremental"}};

}  // namespace

std::string ToString(MapEstimator estimator) { return NameOf(kEstimatorNames, estimator); }
MapEstimator MapEstimatorFromString(const std::string& name) {
  return ValueNamed(kEstimatorNames, name, "map estimator");
}
std::vector<std::string> MapEstimatorNames() { return NamesOf(kEstimatorNames); }

const OptionTable<LocalMapOptions>& LocalMapOptionTable() {
  using O = LocalMapOptions;
  static const OptionTable<O> table = [] {
    OptionTable<O> t = {
        RADARGAUSS_OPTION(O, "azimuth_std", azimuth_std_deg)
            .In(0.0, kMaxAngularNoiseDeg)
            .Unit("deg")
            .Sensor()
            .Help("the radar's azimuth noise: map Gaussians at least this angle x range wide"),
        RADARGAUSS_OPTION(O, "elevation_std", elevation_std_deg)
            .In(0.0, kMaxAngularNoiseDeg)
            .Unit("deg")
            .Sensor()
            .Help("the radar's elevation noise: map Gaussians at least this angle x range high"),
        RADARGAUSS_OPTION(O, "active_radius", active_radius)
            .Above(0.0)
            .Unit("m")
            .Help("radius of the active map around the radar"),
        RADARGAUSS_OPTION(O, "keep_evicted", keep_evicted)
            .Help("keep the Gaussians that leave the active map for the odometry's map file (false: memory bounded "
                  "by the active map, no map file)"),
        RADARGAUSS_OPTION(O, "region", region).Above(0.0).Unit("m").Help("edge of the map regions fitted together"),
        RADARGAUSS_OPTION(O, "region_capacity", region_capacity)
            .In(4, 1e6)
            .NotBelow("region_min_points")
            .Help("points a region keeps (the newest)"),
        RADARGAUSS_OPTION(O, "region_min_points", min_points).In(1, 1e6).Help("points a region's first fit needs"),
        RADARGAUSS_CHOICE(O, "map_estimator", estimator, MapEstimatorNames(), MapEstimatorFromString)
            .Help("how region Gaussians follow their points: refit (k-means + EM) or incremental"),
        RADARGAUSS_OPTION(O, "republish_kl", republish_kl)
            .AtLeast(0.0)
            .Unit("nats")
            .Help("incremental map: KL a Gaussian moves before the matching map gets it again"),
        RADARGAUSS_OPTION(O, "refit_growth", refit_growth)
            .Above(0.0)
            .Help("refit a region once its new points reach this share"),
    };
    AppendNested(
        t, GaussianMapOptionTable(), +[](O & o) -> auto& { return o.gaussians; }, "gaussians");
    AppendNested(
        t, RcsFitOptionTable(), +[](O & o) -> auto& { return o.rcs; }, "rcs");
    AppendNested(
        t, MatchingMapOptionTable(), +[](O & o) -> auto& { return o.matching; }, "matching");
    return t;
  }();
  return table;
}

void ValidateOptions(const LocalMapOptions& o) { CheckOptions(LocalMapOptionTable(), o); }

LocalMap::LocalMap(const LocalMapOptions& options) : options_(options), map_(std::make_shared<GaussianMap>()) {
  ValidateOptions(options_);
  options_.matching.updatable = true;
  map_->incidence = options_.rcs.incidence;
  matching_ = std::make_unique<MatchingMap>(std::shared_ptr<const GaussianMap>(map_), options_.matching);
}

std::uint32_t LocalMap::NewSlot() {
  if (!free_slots_.empty()) {
    const std::uint32_t slot = free_slots_.back();
    free_slots_.pop_back();
    return slot;
  }
  map_->gaussians.emplace_back();
  return std::uint32_t(map_->gaussians.size() - 1);
}

void LocalMap::FreeSlot(std::uint32_t slot, std::vector<std::uint32_t>& removed) {
  removed.push_back(slot);
  free_slots_.push_back(slot);
  map_->gaussians[slot] = Gaussian();
}

std::size_t LocalMap::Insert(const std::vector<Eigen::Vector3d>& points, const std::vector<double>& rcs,
                             const SE3d& pose) {
  const bool has_rcs = !rcs.empty();
  if (has_rcs && rcs.size() != points.size()) throw std::invalid_argument("LocalMap::Insert: one RCS per point");
  const std::uint32_t pose_id = std::uint32_t(poses_.size());
  poses_.push_back(pose);
  const bool incremental = options_.estimator == MapEstimator::kIncremental;
  std::vector<VoxelKey> touched;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) continue;
    const VoxelKey key = VoxelOf(points[i], options_.region);
    Region& region = regions_[key];
    region.has_rcs = has_rcs;
    const double value = has_rcs ? rcs[i] : 0.0;
    std::size_t slot = region.points.size();
    if (slot < options_.region_capacity) {
      region.points.push_back(points[i]);
      region.rcs.push_back(value);
      region.pose.push_back(pose_id);
      if (incremental) {
        region.member.push_back(-1);
        region.direction.emplace_back(Eigen::Vector3d::Zero());
      }
    } else {  // full: the newest point replaces the oldest
      slot = region.next;
      if (incremental) Forget(region, slot);
      region.points[slot] = points[i];
      region.rcs[slot] = value;
      region.pose[slot] = pose_id;
      region.next = (region.next + 1) % options_.region_capacity;
    }
    if (incremental) Assign(region, slot);
    ++region.added;
    touched.push_back(key);
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  std::vector<std::uint32_t> changed, removed;
  std::size_t refitted = 0;
  std::vector<Region*> due;
  for (const VoxelKey& key : touched) {
    Region& region = regions_[key];
    if (incremental) {
      const std::size_t before = changed.size() + removed.size();
      Maintain(region, changed, removed);
      refitted += changed.size() + removed.size() > before;
      continue;
    }
    if (region.fitted == 0 ? region.points.size() >= options_.min_points
                           : double(region.added) >= options_.refit_growth * double(region.fitted)) {
      due.push_back(&region);
    }
  }
  // Each due region's fit reads only its own points and the poses, so the
  // fits run side by side; their slots are then given in region order, as
  // one region after another would give them.
  std::vector<GaussianMap> fits(due.size());
  tbb::parallel_for(std::size_t(0), due.size(), [&](std::size_t r) { fits[r] = Fit(*due[r]); });
  for (std::size_t r = 0; r < due.size(); ++r) Replace(*due[r], std::move(fits[r]), changed, removed);
  refitted += due.size();
  if (!changed.empty() || !removed.empty()) matching_->Update(changed, removed);
  ++version_;  // the points changed, refitted or not
  return refitted;
}

GaussianMap LocalMap::Fit(const Region& region) const {
  std::vector<int> association;
  GaussianMap fitted;
  fitted.gaussians = BuildGaussians(region.points, options_.gaussians, {}, &association);
  if (options_.azimuth_std_deg > 0.0 || options_.elevation_std_deg > 0.0) FloorAtRange(region, association, fitted);
  if (region.has_rcs) {
    // The members' poses, renumbered for a cloud of this region alone.
    MapCloud cloud;
    cloud.points = region.points;
    cloud.rcs = region.rcs;
    cloud.has_rcs = true;
    std::unordered_map<std::uint32_t, std::uint32_t> local;
    for (const std::uint32_t id : region.pose) {
      const auto [it, inserted] = local.try_emplace(id, std::uint32_t(cloud.poses.size()));
      if (inserted) cloud.poses.push_back(poses_[id]);
      cloud.scan.push_back(it->second);
    }
    FitRcsModels(fitted, cloud, association, options_.rcs);
  }
  return fitted;
}

void LocalMap::Replace(Region& region, GaussianMap fitted, std::vector<std::uint32_t>& changed,
                       std::vector<std::uint32_t>& removed) {
  for (const std::uint32_t slot : region.gaussians) FreeSlot(slot, removed);
  region.gaussians.clear();
  region.fitted = region.points.size();
  region.added = 0;
  for (Gaussian& g : fitted.gaussians) {
    const std::uint32_t slot = NewSlot();
    map_->gaussians[slot] = std::move(g);
    region.gaussians.push_back(slot);
    changed.push_back(slot);
  }
}

void LocalMap::FloorAtRange(const Region& region, const std::vector<int>& association, GaussianMap& fitted) const {
  std::vector<double> range_sum(fitted.gaussians.size(), 0.0);
  std::vector<std::size_t> members(fitted.gaussians.size(), 0);
  for (std::size_t i = 0; i < region.points.size(); ++i) {
    if (association[i] < 0) continue;
    range_sum[association[i]] += (region.points[i] - poses_[region.pose[i]].translation()).norm();
    ++members[association[i]];
  }
  for (std::size_t g = 0; g < fitted.gaussians.size(); ++g) {
    if (members[g] == 0) continue;
    Eigen::Matrix3d& covariance = fitted.gaussians[g].covariance;
    covariance = FlooredAtRange(covariance, range_sum[g] / double(members[g]), options_);
  }
}

Eigen::Matrix3d FlooredAtRange(const Eigen::Matrix3d& covariance, double range, const LocalMapOptions& options) {
  const double azimuth = std::tan(options.azimuth_std_deg * M_PI / 180.0);
  const double elevation = std::tan(options.elevation_std_deg * M_PI / 180.0);
  const double min_std = options.gaussians.min_std;
  const Eigen::Vector3d floor(std::max(min_std, azimuth * range), std::max(min_std, azimuth * range),
                              std::max(min_std, elevation * range));
  // Clamped where the floor is the unit sphere, then scaled back.
  const Eigen::Matrix3d whitened = floor.cwiseInverse().asDiagonal() * covariance * floor.cwiseInverse().asDiagonal();
  return floor.asDiagonal() * ClampCovariance(whitened, 1.0) * floor.asDiagonal();
}

std::size_t LocalMap::Evict(const Eigen::Vector3d& position) {
  std::vector<std::uint32_t> removed;
  std::size_t left = 0;
  const double half = 0.5 * options_.region;
  for (auto it = regions_.begin(); it != regions_.end();) {
    const Eigen::Vector3d centre =
        Eigen::Vector3d(double(it->first.x), double(it->first.y), double(it->first.z)) * options_.region +
        Eigen::Vector3d::Constant(half);
    if ((centre - position).norm() <= options_.active_radius) {
      ++it;
      continue;
    }
    for (const std::uint32_t slot : it->second.gaussians) {
      if (options_.keep_evicted) evicted_.push_back(map_->gaussians[slot]);
      map_->gaussians[slot] = Gaussian();
      removed.push_back(slot);
      free_slots_.push_back(slot);
    }
    it = regions_.erase(it);
    ++left;
  }
  if (!removed.empty()) matching_->Update({}, removed);
  if (left > 0) ++version_;
  return left;
}

std::size_t LocalMap::points() const {
  std::size_t n = 0;
  for (const auto& entry : regions_) n += entry.second.points.size();
  return n;
}

std::vector<Eigen::Vector3d> LocalMap::ActivePoints() const {
  std::vector<Eigen::Vector3d> all;
  all.reserve(points());
  for (const auto& entry : regions_) all.insert(all.end(), entry.second.points.begin(), entry.second.points.end());
  return all;
}

GaussianMap LocalMap::GlobalMap() const {
  GaussianMap global;
  global.incidence = map_->incidence;
  global.gaussians = evicted_;
  for (const auto& entry : regions_) {
    for (const std::uint32_t slot : entry.second.gaussians) global.gaussians.push_back(map_->gaussians[slot]);
  }
  return global;
}

std::size_t LocalMap::MemoryBytes() const {
  std::size_t bytes =
      matching_->MemoryBytes() + map_->gaussians.capacity() * sizeof(Gaussian) + poses_.capacity() * sizeof(SE3d);
  for (const auto& entry : regions_) {
    const Region& r = entry.second;
    bytes += 96 + r.points.capacity() * sizeof(Eigen::Vector3d) + r.rcs.capacity() * sizeof(double) +
             r.pose.capacity() * sizeof(std::uint32_t) + r.gaussians.capacity() * sizeof(std::uint32_t);
  }
  return bytes;
}

}  // namespace radargauss
