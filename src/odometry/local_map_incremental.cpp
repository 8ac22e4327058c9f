// SPDX-License-Identifier: BSD-3-Clause
// The incremental estimator of odometry's local map (docs/design/odometry.md, "The
// incremental map"): each point joins the nearest Gaussian of its region
// whose gate holds it and updates that Gaussian's sufficient statistics; the
// points no gate holds seed new Gaussians by build-map's estimator once there
// are enough of them; the region's Gaussian of largest squared error is split
// in two while the region has fewer than build-map would fit; and a Gaussian
// reaches the matching map only once it has moved since it last did.
#include <algorithm>
#include <cmath>

#include "radargauss/map/builder.hpp"
#include "radargauss/odometry/local_map.hpp"

namespace radargauss {

namespace {

// The Gaussian a component's statistics give: build-map's clamp, then the
// floor of the radar's angular noise at its members' mean range.
Gaussian CurrentGaussian(const PointStatistics& stats, double range_sum, const LocalMapOptions& options) {
  Gaussian g;
  g.mean = stats.mean;
  g.covariance = ClampCovariance(stats.Covariance(), options.gaussians.min_std);
  g.point_count = std::uint32_t(stats.count);
  if (options.azimuth_std_deg > 0.0 || options.elevation_std_deg > 0.0) {
    g.covariance = FlooredAtRange(g.covariance, range_sum / double(stats.count), options);
  }
  return g;
}

std::int64_t DownsampleKey(const Eigen::Vector3d& point, double voxel) {
  const VoxelKey key = VoxelOf(point, voxel);
  return PackVoxelKey(key.x, key.y, key.z);
}

// The unit incidence direction of a member at `point` seen from `pose` for a
// Gaussian at `mean`, facing the radar (docs/design/map.md, "RCS models"); zero
// when it has none.
Eigen::Vector3d IncidenceDirection(const SE3d& pose, const Eigen::Vector3d& point, const Eigen::Vector3d& mean,
                                   IncidenceModel model) {
  const Eigen::Matrix3d radar_from_world = pose.rotation().Matrix().transpose();
  const Eigen::Vector3d u = IncidenceVector<double>(model, radar_from_world * (point - pose.translation()),
                                                    radar_from_world * (mean - pose.translation()));
  if (u.squaredNorm() < 1e-18) return Eigen::Vector3d::Zero();
  return FacingSign(u) * u.normalized();
}

}  // namespace

void LocalMap::Assign(Region& region, std::size_t i) {
  const Eigen::Vector3d& point = region.points[i];
  ++region.voxels[DownsampleKey(point, options_.gaussians.downsample_voxel)];
  const double gate_sq = options_.gaussians.association_gate * options_.gaussians.association_gate;
  std::int32_t best = -1;
  double best_d2 = gate_sq;
  for (std::size_t c = 0; c < region.components.size(); ++c) {
    const Component& component = region.components[c];
    if (component.slot == kNoSlot) continue;
    const Eigen::Vector3d e = point - map_->gaussians[component.slot].mean;
    const double d2 = e.dot(component.information * e);
    if (d2 <= best_d2) {
      best_d2 = d2;
      best = std::int32_t(c);
    }
  }
  region.member[i] = -1;
  if (best >= 0) {
    Join(region, i, best);
  } else {
    ++region.pending;
  }
}

void LocalMap::Join(Region& region, std::size_t i, std::int32_t c) {
  Component& component = region.components[c];
  const Eigen::Vector3d& point = region.points[i];
  const SE3d& pose = poses_[region.pose[i]];
  if (component.rcs)
    region.direction[i] = IncidenceDirection(pose, point, component.points.mean, options_.rcs.incidence);
  component.points.Add(point);
  component.range_sum += (point - pose.translation()).norm();
  if (component.rcs && region.direction[i].squaredNorm() > 0.0) component.rcs->Add(region.direction[i], region.rcs[i]);
  ++component.changes;
  region.member[i] = c;
}

void LocalMap::Forget(Region& region, std::size_t i) {
  const Eigen::Vector3d& point = region.points[i];
  const auto voxel = region.voxels.find(DownsampleKey(point, options_.gaussians.downsample_voxel));
  if (voxel != region.voxels.end() && --voxel->second == 0) region.voxels.erase(voxel);
  const std::int32_t c = region.member[i];
  if (c < 0) {
    region.pending -= region.pending > 0;
    return;
  }
  Component& component = region.components[c];
  component.points.Remove(point);
  component.range_sum -= (point - poses_[region.pose[i]].translation()).norm();
  if (component.rcs && region.direction[i].squaredNorm() > 0.0)
    component.rcs->Remove(region.direction[i], region.rcs[i]);
  ++component.changes;
  region.member[i] = -1;
}

void LocalMap::Recompute(Region& region, std::int32_t c) {
  Component& component = region.components[c];
  component.points = PointStatistics();
  component.range_sum = 0.0;
  std::vector<std::size_t> members;
  std::vector<double> rcs;
  for (std::size_t i = 0; i < region.points.size(); ++i) {
    if (region.member[i] != c) continue;
    members.push_back(i);
    rcs.push_back(region.rcs[i]);
    component.points.Add(region.points[i]);
    component.range_sum += (region.points[i] - poses_[region.pose[i]].translation()).norm();
  }
  component.rcs.reset();
  if (region.has_rcs) component.rcs = std::make_unique<RcsStatistics>(NormaliseRcs(rcs));
  // The directions at the mean of all members.
  for (const std::size_t i : members) {
    if (!component.rcs) break;
    region.direction[i] =
        IncidenceDirection(poses_[region.pose[i]], region.points[i], component.points.mean, options_.rcs.incidence);
    if (region.direction[i].squaredNorm() > 0.0) component.rcs->Add(region.direction[i], region.rcs[i]);
  }
  component.reshaped = true;
}

void LocalMap::Maintain(Region& region, std::vector<std::uint32_t>& changed, std::vector<std::uint32_t>& removed) {
  if (region.points.size() < options_.min_points) return;
  if (region.pending >= options_.min_points &&
      double(region.pending) >= (1.0 + options_.refit_growth) * double(region.pending_at_seeding)) {
    Seed(region);
  }
  const std::size_t target = std::max<std::size_t>(
      1, std::size_t(std::llround(double(region.voxels.size()) / options_.gaussians.points_per_gaussian)));
  Merge(region, target);
  Split(region, target);
  Publish(region, changed, removed);
}

void LocalMap::Seed(Region& region) {
  std::vector<std::size_t> pending;
  std::vector<Eigen::Vector3d> points;
  for (std::size_t i = 0; i < region.points.size(); ++i) {
    if (region.member[i] >= 0) continue;
    pending.push_back(i);
    points.push_back(region.points[i]);
  }
  std::vector<int> association;
  const std::vector<Gaussian> seeds = BuildGaussians(points, options_.gaussians, {}, &association);
  const std::int32_t first = std::int32_t(region.components.size());
  region.components.resize(region.components.size() + seeds.size());
  for (std::size_t k = 0; k < pending.size(); ++k) {
    if (association[k] < 0) continue;
    region.member[pending[k]] = first + association[k];
    --region.pending;
  }
  for (std::int32_t c = first; c < std::int32_t(region.components.size()); ++c) Recompute(region, c);
  region.pending_at_seeding = region.pending;
}

void LocalMap::Merge(Region& region, std::size_t target) {
  std::size_t live = 0;
  for (const Component& component : region.components) live += component.points.count > 0;
  while (live > target) {
    // The pair whose union adds least squared error (Ward's criterion,
    // n m / (n + m) |mu_n - mu_m|^2), from the statistics alone.
    std::int32_t keep = -1, fold = -1;
    double least = INFINITY;
    for (std::size_t a = 0; a < region.components.size(); ++a) {
      const PointStatistics& p = region.components[a].points;
      if (p.count == 0) continue;
      for (std::size_t b = a + 1; b < region.components.size(); ++b) {
        const PointStatistics& q = region.components[b].points;
        if (q.count == 0) continue;
        const double n = double(p.count), m = double(q.count);
        const double cost = n * m / (n + m) * (p.mean - q.mean).squaredNorm();
        if (cost < least) {
          least = cost;
          keep = std::int32_t(a);
          fold = std::int32_t(b);
        }
      }
    }
    if (keep < 0) return;
    for (std::int32_t& m : region.member) {
      if (m == fold) m = keep;
    }
    region.components[fold].points = PointStatistics();  // empty: Publish retires it
    region.components[fold].rcs.reset();
    Recompute(region, keep);
    --live;
  }
}

void LocalMap::Split(Region& region, std::size_t target) {
  std::vector<char> unsplittable(region.components.size(), 0);
  while (region.components.size() < target) {
    // The component of largest squared error, as bisecting k-means picks.
    std::int32_t widest = -1;
    double widest_error = 0.0;
    for (std::size_t c = 0; c < region.components.size(); ++c) {
      const double error = region.components[c].points.scatter.trace();
      if (!unsplittable[c] && region.components[c].points.count >= 2 && error > widest_error) {
        widest_error = error;
        widest = std::int32_t(c);
      }
    }
    if (widest < 0) return;
    std::vector<std::size_t> members;
    std::vector<Eigen::Vector3d> points;
    for (std::size_t i = 0; i < region.points.size(); ++i) {
      if (region.member[i] != widest) continue;
      members.push_back(i);
      points.push_back(region.points[i]);
    }
    const std::vector<std::vector<std::uint32_t>> halves = KMeansPartition(points, 2, options_.gaussians);
    if (halves.size() < 2) {
      unsplittable[widest] = 1;
      continue;
    }
    const std::int32_t added = std::int32_t(region.components.size());
    region.components.emplace_back();
    unsplittable.push_back(0);
    for (const std::uint32_t k : halves[1]) region.member[members[k]] = added;
    Recompute(region, widest);
    Recompute(region, added);
  }
}

void LocalMap::Publish(Region& region, std::vector<std::uint32_t>& changed, std::vector<std::uint32_t>& removed) {
  bool emptied = false;
  for (std::size_t c = 0; c < region.components.size(); ++c) {
    Component& component = region.components[c];
    if (component.points.count == 0) {
      emptied = true;
      continue;
    }
    // The KL is checked once a tenth of the members have come or gone.
    if (!component.reshaped && 10 * std::size_t(component.changes) < component.points.count) continue;
    component.changes = 0;
    const Gaussian current = CurrentGaussian(component.points, component.range_sum, options_);
    const bool moved = component.slot == kNoSlot || component.reshaped ||
                       KullbackLeibler(current.mean, current.covariance, map_->gaussians[component.slot].mean,
                                       map_->gaussians[component.slot].covariance) > options_.republish_kl;
    if (!moved) continue;
    if (component.rcs && (!component.rcs->normalisation.valid || component.rcs->outliers > component.rcs->inliers)) {
      Recompute(region, std::int32_t(c));
    }
    if (component.slot == kNoSlot) component.slot = NewSlot();
    Gaussian& published = map_->gaussians[component.slot];
    published = current;
    if (component.rcs) published.rcs = component.rcs->Solve(options_.rcs);
    component.information = current.covariance.inverse();
    changed.push_back(component.slot);
    component.reshaped = false;
  }
  if (emptied) Retire(region, removed);
  region.gaussians.clear();
  for (const Component& component : region.components) region.gaussians.push_back(component.slot);
}

void LocalMap::Retire(Region& region, std::vector<std::uint32_t>& removed) {
  std::vector<std::int32_t> renumber(region.components.size(), -1);
  std::vector<Component> kept;
  for (std::size_t c = 0; c < region.components.size(); ++c) {
    Component& component = region.components[c];
    if (component.points.count == 0) {
      if (component.slot != kNoSlot) FreeSlot(component.slot, removed);
      continue;
    }
    renumber[c] = std::int32_t(kept.size());
    kept.push_back(std::move(component));
  }
  region.components = std::move(kept);
  for (std::int32_t& m : region.member) {
    if (m >= 0) m = renumber[m];
  }
}

}  // namespace radargauss
