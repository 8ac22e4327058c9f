// SPDX-License-Identifier: BSD-3-Clause
#include "radargauss/map/matching_map.hpp"

#include <algorithm>
#include <exception>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "radargauss/map/builder.hpp"
#include "radargauss/core/names.hpp"

namespace radargauss {

namespace {

// The moment-matched mixture of gaussians[members] (ascending ids), weighted
// by their member counts: one merge cell of a merged coarse level.
Gaussian MergeOf(const std::vector<Gaussian>& gaussians, const std::vector<std::uint32_t>& members) {
  double weight = 0.0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();  // sum w (Sigma + mu mu^T)
  std::uint32_t points = 0;
  for (const std::uint32_t id : members) {
    const Gaussian& g = gaussians[id];
    const double w = std::max<std::uint32_t>(g.point_count, 1);
    weight += w;
    sum += w * g.mean;
    second += w * (g.covariance + g.mean * g.mean.transpose());
    points += g.point_count;
  }
  Gaussian merged;
  merged.mean = sum / weight;
  const Eigen::Matrix3d covariance = second / weight - merged.mean * merged.mean.transpose();
  merged.covariance = 0.5 * (covariance + covariance.transpose());
  merged.point_count = points;
  return merged;
}

// One Gaussian per voxel of side `cell` (the voxel of its mean), in voxel
// order: the mixture of the Gaussians whose means fall in it.
std::vector<Gaussian> MergedGaussians(const std::vector<Gaussian>& gaussians, double cell) {
  std::vector<Eigen::Vector3d> means(gaussians.size());
  for (std::size_t i = 0; i < gaussians.size(); ++i) means[i] = gaussians[i].mean;
  const std::vector<std::vector<std::uint32_t>> voxels = GroupByVoxel(means, cell);
  std::vector<Gaussian> merged;
  merged.reserve(voxels.size());
  for (const std::vector<std::uint32_t>& members : voxels) merged.push_back(MergeOf(gaussians, members));
  return merged;
}

const NamedValue<CoarseLevels> kCoarseNames[] = {{CoarseLevels::kMerged, "merged"},
                                                 {CoarseLevels::kInflated, "inflated"}};

}  // namespace

std::string ToString(CoarseLevels coarse) { return NameOf(kCoarseNames, coarse); }
CoarseLevels CoarseLevelsFromString(const std::string& name) { return ValueNamed(kCoarseNames, name, "coarse levels"); }
std::vector<std::string> CoarseLevelsNames() { return NamesOf(kCoarseNames); }

const OptionTable<MatchingMapOptions>& MatchingMapOptionTable() {
  using O = MatchingMapOptions;
  static const OptionTable<O> table = [] {
    Option<O> sigmas = RADARGAUSS_OPTION(O, "coarse_sigmas", inflation)
                           .Count(1, 8)
                           .In(0.0, kMaxCoarseSigma)
                           .Unit("m")
                           .Help("blur sigma_k of the coarse levels, coarse first; 0: the exact map alone");
    sigmas.get = [](const O& o) { return OptionValue(o.inflation.empty() ? std::vector<double>{0.0} : o.inflation); };
    sigmas.set = [](O& o, const OptionValue& v) {
      o.inflation = std::get<std::vector<double>>(v);
      if (o.inflation == std::vector<double>{0.0}) o.inflation.clear();
    };
    return OptionTable<O>{
        RADARGAUSS_CHOICE(O, "coarse_levels", coarse, CoarseLevelsNames(), CoarseLevelsFromString)
            .Help("coarse levels: merged or inflated"),
        std::move(sigmas),
        RADARGAUSS_OPTION(O, "index_cell", index_cell)
            .In(kMinIndexCell, kMaxIndexCell)
            .Unit("m")
            .Help("cell of the exact level's spatial index"),
        RADARGAUSS_OPTION(O, "coarse_gate", coarse_gate)
            .In(kMinCoarseGate, kMaxCoarseGate)
            .Help("tau on the coarse levels"),
    };
  }();
  return table;
}

MatchingMap::MatchingMap(GaussianMap map, const MatchingMapOptions& options)
    : MatchingMap(std::make_shared<const GaussianMap>(std::move(map)), options) {}

MatchingMap::MatchingMap(std::shared_ptr<const GaussianMap> shared, const MatchingMapOptions& options)
    : map_(std::move(shared)), coarse_gate_(options.coarse_gate), coarse_(options.coarse) {
  if (!map_) throw std::invalid_argument("MatchingMap needs a map");
  const GaussianMap& map = *map_;
  CheckOptions(MatchingMapOptionTable(), options);
  for (const double sigma : options.inflation) {
    if (!(sigma > 0.0)) throw std::invalid_argument("coarse_sigmas: a coarse level's sigma must be > 0 m");
    sigmas_.push_back(sigma);
    const double cell = std::max(options.index_cell, CoarseIndexCell(options.coarse, sigma));
    if (options.updatable) {
      levels_.push_back(GaussianIndex::Updatable(cell, options.coarse_gate));
      continue;
    }
    std::vector<Gaussian> level = options.coarse == CoarseLevels::kMerged
                                      ? MergedGaussians(map.gaussians, kMergeCellPerSigma * sigma)
                                      : map.gaussians;
    for (Gaussian& g : level) g.covariance += sigma * sigma * Eigen::Matrix3d::Identity();
    levels_.emplace_back(level, cell, options.coarse_gate);
  }
  if (!options.updatable) {
    levels_.emplace_back(map.gaussians, options.index_cell);
    indexed_ = map.gaussians.size();
    return;
  }
  levels_.push_back(GaussianIndex::Updatable(options.index_cell));
  coarse_states_.resize(sigmas_.size());
  std::vector<std::uint32_t> all(map.gaussians.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = std::uint32_t(i);
  Update(all, {});
}

void MatchingMap::Update(const std::vector<std::uint32_t>& changed, const std::vector<std::uint32_t>& removed) {
  if (!levels_.back().updatable()) throw std::logic_error("MatchingMap::Update needs a map built updatable");
  live_.resize(map_->gaussians.size(), 0);
  for (const std::uint32_t id : removed) {
    if (id < live_.size() && live_[id]) --indexed_;
    if (id < live_.size()) live_[id] = 0;
  }
  for (const std::uint32_t id : changed) {
    if (id < live_.size() && !live_[id]) ++indexed_;
    if (id < live_.size()) live_[id] = 1;
  }
  // The levels are apart (each its own index and state), so they update
  // side by side; a failure is reported as the coarsest failing level's.
  std::vector<std::exception_ptr> failures(levels_.size());
  tbb::parallel_for(std::size_t(0), levels_.size(), [&](std::size_t level) {
    try {
      if (level < sigmas_.size()) {
        UpdateCoarse(level, changed, removed);
      } else {
        levels_.back().Update(map_->gaussians, changed, removed);
      }
    } catch (...) {
      failures[level] = std::current_exception();
    }
  });
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
}

void MatchingMap::UpdateCoarse(std::size_t level, const std::vector<std::uint32_t>& changed,
                               const std::vector<std::uint32_t>& removed) {
  CoarseState& state = coarse_states_[level];
  const std::vector<Gaussian>& exact = map_->gaussians;
  const Eigen::Matrix3d blur = sigmas_[level] * sigmas_[level] * Eigen::Matrix3d::Identity();
  if (coarse_ == CoarseLevels::kInflated) {  // the exact map's ids, blurred
    state.gaussians.resize(exact.size());
    for (const std::uint32_t id : changed) {
      state.gaussians[id] = exact[id];
      state.gaussians[id].covariance += blur;
    }
    levels_[level].Update(state.gaussians, changed, removed);
    return;
  }
  const double cell = kMergeCellPerSigma * sigmas_[level];
  state.cell_of.resize(exact.size());
  state.listed.resize(exact.size(), 0);
  std::vector<VoxelKey> dirty;
  const auto leave = [&](std::uint32_t id) {
    if (id >= state.listed.size() || !state.listed[id]) return;
    std::vector<std::uint32_t>& members = state.cells[state.cell_of[id]].second;
    members.erase(std::lower_bound(members.begin(), members.end(), id));
    dirty.push_back(state.cell_of[id]);
    state.listed[id] = 0;
  };
  for (const std::uint32_t id : removed) leave(id);
  for (const std::uint32_t id : changed) leave(id);
  for (const std::uint32_t id : changed) {
    if (state.listed[id]) continue;  // listed twice in `changed`
    const VoxelKey key = VoxelOf(exact[id].mean, cell);
    auto [it, inserted] = state.cells.try_emplace(key);
    if (inserted) {
      if (state.free_slots.empty()) {
        it->second.first = std::uint32_t(state.gaussians.size());
        state.gaussians.emplace_back();
      } else {
        it->second.first = state.free_slots.back();
        state.free_slots.pop_back();
      }
    }
    std::vector<std::uint32_t>& members = it->second.second;
    members.insert(std::upper_bound(members.begin(), members.end(), id), id);
    state.cell_of[id] = key;
    state.listed[id] = 1;
    dirty.push_back(key);
  }
  std::sort(dirty.begin(), dirty.end());
  dirty.erase(std::unique(dirty.begin(), dirty.end()), dirty.end());
  std::vector<std::uint32_t> changed_slots, removed_slots;
  for (const VoxelKey& key : dirty) {
    const auto it = state.cells.find(key);
    const std::uint32_t slot = it->second.first;
    if (it->second.second.empty()) {
      removed_slots.push_back(slot);
      state.free_slots.push_back(slot);
      state.cells.erase(it);
      continue;
    }
    state.gaussians[slot] = MergeOf(exact, it->second.second);
    state.gaussians[slot].covariance += blur;
    changed_slots.push_back(slot);
  }
  levels_[level].Update(state.gaussians, changed_slots, removed_slots);
}

std::size_t MatchingMap::MemoryBytes() const {
  std::size_t bytes = 0;
  for (const GaussianIndex& level : levels_) bytes += level.MemoryBytes();
  for (const CoarseState& state : coarse_states_) {
    bytes += state.gaussians.capacity() * sizeof(Gaussian) + state.cell_of.capacity() * sizeof(VoxelKey);
    for (const auto& entry : state.cells) bytes += 64 + entry.second.second.capacity() * sizeof(std::uint32_t);
  }
  return bytes;
}

}  // namespace radargauss
