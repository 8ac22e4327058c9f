// SPDX-License-Identifier: BSD-3-Clause
// The updatable spatial index of odometry's local map (docs/design.md,
// "Odometry"): the cells a change touches get new lists appended to the
// entries (or rewritten in place when they fit the old), and the entries are
// compacted once stale ones outnumber the live.
#include <algorithm>
#include <stdexcept>
#include <utility>

#include "radargauss/map/gaussian_map.hpp"

namespace radargauss {

GaussianIndex GaussianIndex::Updatable(double cell_size, double extent_sigmas) {
  GaussianIndex index(std::vector<Gaussian>(), cell_size, extent_sigmas);
  index.updatable_ = true;
  return index;
}

void GaussianIndex::Compact(std::size_t extra_cells) {
  std::vector<Cell> live;
  if (!cells_.empty()) {
    for (std::size_t slot = 0; slot < cells_.size(); ++slot) {
      const Cell& cell = cells_[slot];
      if (cell.key != kEmptyCell && cell.end > cell.begin) live.push_back(cell);
    }
  }
  std::sort(live.begin(), live.end(), [](const Cell& a, const Cell& b) { return a.key < b.key; });
  std::vector<std::uint32_t> entries;
  std::size_t live_entries = 0;
  for (const Cell& cell : live) live_entries += cell.end - cell.begin;
  entries.reserve(2 * live_entries + 64);
  // Room for twice the cells there will be: the table stays at most half full
  // until the next compaction.
  cells_.Reset(2 * (live.size() + extra_cells) + 8, Cell());
  for (const Cell& cell : live) {
    Cell& moved = cells_[Slot(cell.key)];
    moved.key = cell.key;
    moved.begin = std::uint32_t(entries.size());
    entries.insert(entries.end(), cell_entries_.begin() + cell.begin, cell_entries_.begin() + cell.end);
    moved.end = std::uint32_t(entries.size());
  }
  cell_entries_ = std::move(entries);
  cell_count_ = live.size();
  stale_entries_ = 0;
}

void GaussianIndex::Update(const std::vector<Gaussian>& gaussians, const std::vector<std::uint32_t>& changed,
                           const std::vector<std::uint32_t>& removed) {
  if (!updatable_) throw std::logic_error("GaussianIndex::Update needs an index made by GaussianIndex::Updatable");
  std::uint32_t top = std::uint32_t(gaussians_.size());
  for (const std::uint32_t id : changed) {
    if (id >= gaussians.size()) throw std::out_of_range("GaussianIndex::Update: changed id beyond the Gaussians");
    top = std::max(top, id + 1);
  }
  gaussians_.resize(top);
  listed_cells_.resize(top);
  // The ids leaving their cells, and the cells each changed Gaussian joins.
  std::vector<char> leaving(top, 0);
  std::vector<std::int64_t> dirty;
  const auto leave = [&](std::uint32_t id) {
    if (id >= top || leaving[id]) return;
    leaving[id] = 1;
    dirty.insert(dirty.end(), listed_cells_[id].begin(), listed_cells_[id].end());
    std::vector<std::int64_t>().swap(listed_cells_[id]);  // frees the capacity (`= {}` keeps it)
  };
  for (const std::uint32_t id : removed) leave(id);
  for (const std::uint32_t id : changed) leave(id);
  // (cell, id) of every joining listing, sorted: each cell's joiners are a
  // run, in id order.
  std::vector<std::pair<std::int64_t, std::uint32_t>> joining;
  for (const std::uint32_t id : changed) {
    if (!listed_cells_[id].empty()) continue;  // listed twice in `changed`
    Index(gaussians[id], id, listed_cells_[id]);
    for (const std::int64_t key : listed_cells_[id]) joining.emplace_back(key, id);
    dirty.insert(dirty.end(), listed_cells_[id].begin(), listed_cells_[id].end());
  }
  std::sort(joining.begin(), joining.end());
  std::sort(dirty.begin(), dirty.end());
  dirty.erase(std::unique(dirty.begin(), dirty.end()), dirty.end());
  if (cells_.empty() || 2 * (cell_count_ + dirty.size()) > cells_.size()) Compact(dirty.size());
  // Each touched cell's list: its entries that stay merged with those that
  // join, both in id order as the static index lists them (ties go to the
  // smallest id).
  std::vector<std::uint32_t> staying, joined;
  auto next_join = joining.begin();
  // The home slots are fetched a few keys ahead: each is a cache miss.
  constexpr std::size_t kAhead = 8;
  for (std::size_t k = 0; k < std::min(kAhead, dirty.size()); ++k) {
    __builtin_prefetch(&cells_[cells_.HomeSlot(std::uint64_t(dirty[k]))]);
  }
  for (std::size_t d = 0; d < dirty.size(); ++d) {
    if (d + kAhead < dirty.size()) __builtin_prefetch(&cells_[cells_.HomeSlot(std::uint64_t(dirty[d + kAhead]))]);
    const std::int64_t key = dirty[d];
    Cell& cell = cells_[Slot(key)];
    staying.clear();
    if (cell.key == key) {
      for (std::uint32_t e = cell.begin; e < cell.end; ++e) {
        if (!leaving[cell_entries_[e]]) staying.push_back(cell_entries_[e]);
      }
      stale_entries_ += cell.end - cell.begin;
    } else {
      cell.key = key;
      ++cell_count_;
    }
    joined.clear();
    for (; next_join != joining.end() && next_join->first == key; ++next_join) joined.push_back(next_join->second);
    // A list that fits in the old one is rewritten in its place; a longer
    // one is appended.
    const std::size_t length = staying.size() + joined.size();
    if (cell.end - cell.begin < length) {
      cell.begin = std::uint32_t(cell_entries_.size());
      cell_entries_.resize(cell_entries_.size() + length);
    } else {
      stale_entries_ -= length;
    }
    std::merge(staying.begin(), staying.end(), joined.begin(), joined.end(), cell_entries_.begin() + cell.begin);
    cell.end = std::uint32_t(cell.begin + length);
  }
  if (stale_entries_ > cell_entries_.size() - stale_entries_ + 1024) Compact(0);
}

}  // namespace radargauss
