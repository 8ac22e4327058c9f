// SPDX-License-Identifier: BSD-3-Clause
// The map as the solvers use it (docs/design/solvers.md, "Coarse to fine"): the
// Gaussians and one spatial index per level, coarse levels first. Odometry's
// local map keeps one that follows its changes (MatchingMap::Update).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "radargauss/map/gaussian_map.hpp"
#include "radargauss/core/options.hpp"

namespace radargauss {

// How the coarse levels of a MatchingMap are made from the map's Gaussians.
// kMerged is the default: from the paper's errors it was faster and at least
// as precise on every data set measured (bench/RESULTS.md, "Coarse levels").
enum class CoarseLevels {
  kInflated,  // every Gaussian, covariance Sigma + sigma_k^2 I
  kMerged,    // per voxel of side kMergeCellPerSigma * sigma_k, the moment-matched
              // mixture of the Gaussians whose means fall in it, + sigma_k^2 I:
              // far fewer candidates per query
};
inline constexpr double kMergeCellPerSigma = 3.0;
// The index cell of a coarse level before MatchingMapOptions::index_cell's
// floor: sigma_k for inflated levels (every Gaussian, blurred); half the merge
// cell for merged ones, whose Gaussians are one per merge cell, so that a
// query still has few candidates and the index is half the size.
inline double CoarseIndexCell(CoarseLevels coarse, double sigma) {
  return coarse == CoarseLevels::kMerged ? 0.5 * kMergeCellPerSigma * sigma : sigma;
}
std::string ToString(CoarseLevels coarse);
CoarseLevels CoarseLevelsFromString(const std::string& name);  // throws std::invalid_argument
std::vector<std::string> CoarseLevelsNames();

// The map as the solvers use it: the Gaussians and coarse-to-fine indexes,
// level k blurred by sigma_k (coarse first), the exact map last
// (docs/design/solvers.md, "Coarse to fine").
// Bounds of the matching structures' sizes: a blur or an index cell beyond
// these is a wrong number (and squared, could overflow the cell counts).
constexpr double kMaxCoarseSigma = 100.0;  // m
constexpr double kMaxIndexCell = 100.0;    // m
// A finer index cell lists a metre-wide Gaussian in millions of cells.
constexpr double kMinIndexCell = 0.1;  // m (0.02 m: 18 s and 1.9 GB for 40 scans)
// The coarse levels' gate in stds: their index boxes grow with its cube.
constexpr double kMinCoarseGate = 1e-3;
constexpr double kMaxCoarseGate = 30.0;

struct MatchingMapOptions {
  std::vector<double> inflation = {1.0, 0.5, 0.25};  // sigma_k of the coarse levels (m), coarse first
  double index_cell = 0.5;  // m: cell of the exact level's index (coarse: max(cell, CoarseIndexCell))
  CoarseLevels coarse = CoarseLevels::kMerged;
  // tau on the coarse levels (Mahalanobis distance to the blurred Gaussians;
  // the exact map uses ScanMatchingOptions::gate). Their indexes cover
  // +/- coarse_gate std, so a smaller gate means fewer candidates per query:
  // faster coarse levels, less reach for large initial errors.
  double coarse_gate = 3.0;
  // An updatable map (MatchingMap::Update), as odometry's local map needs.
  bool updatable = false;
};
// Its options (options.hpp) but `updatable`, which the code that needs an
// updatable map sets; coarse_sigmas [0] stands for no coarse level.
const OptionTable<MatchingMapOptions>& MatchingMapOptionTable();

// The exact map alone: one level, no coarse-to-fine.
inline MatchingMapOptions ExactMapOnly() {
  MatchingMapOptions options;
  options.inflation.clear();
  return options;
}

// A MatchingMap shares its GaussianMap: it takes one by value (move it in;
// a temporary such as ReadMap(path) is kept alive) or a shared pointer.
class MatchingMap {
 public:
  explicit MatchingMap(GaussianMap map, const MatchingMapOptions& options = {});
  explicit MatchingMap(std::shared_ptr<const GaussianMap> map, const MatchingMapOptions& options = {});
  const GaussianMap& map() const { return *map_; }
  std::size_t levels() const { return levels_.size(); }
  const GaussianIndex& level(std::size_t k) const { return levels_[k]; }
  const GaussianIndex& index() const { return levels_.back(); }                        // the exact map
  double sigma(std::size_t k) const { return k < sigmas_.size() ? sigmas_[k] : 0.0; }  // level k's blur (m)
  double coarse_gate() const { return coarse_gate_; }

  // For an updatable map whose owner has changed the shared map in place:
  // re-indexes map().gaussians[id] for every id of `changed` and drops every
  // id of `removed` (a free slot, never associated again), on the exact map
  // and on the coarse levels (a merged level recomputes the merge cells they
  // leave or join). Every level then answers as one built from the listed
  // Gaussians would. Throws std::logic_error on a map built not updatable.
  void Update(const std::vector<std::uint32_t>& changed, const std::vector<std::uint32_t>& removed);
  // The Gaussians indexed on the exact map (an updatable map's live ones).
  std::size_t indexed() const { return indexed_; }
  std::size_t MemoryBytes() const;

 private:
  // A coarse level that can follow updates: its Gaussians by slot and, when
  // merged, which exact-map Gaussians each merge cell holds.
  struct CoarseState {
    std::vector<Gaussian> gaussians;
    std::map<VoxelKey, std::pair<std::uint32_t, std::vector<std::uint32_t>>> cells;  // slot, members by id
    std::vector<VoxelKey> cell_of;  // merged: the merge cell of each exact-map Gaussian
    std::vector<char> listed;       // merged: whether it is in one
    std::vector<std::uint32_t> free_slots;
  };
  void UpdateCoarse(std::size_t level, const std::vector<std::uint32_t>& changed,
                    const std::vector<std::uint32_t>& removed);

  std::shared_ptr<const GaussianMap> map_;
  std::vector<GaussianIndex> levels_;
  std::vector<double> sigmas_;  // of the coarse levels
  double coarse_gate_ = 3.0;
  CoarseLevels coarse_ = CoarseLevels::kMerged;
  std::vector<CoarseState> coarse_states_;  // updatable maps only
  std::vector<char> live_;                  // updatable: exact-map ids indexed
  std::size_t indexed_ = 0;
};

}  // namespace radargauss
