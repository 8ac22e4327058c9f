// SPDX-License-Identifier: BSD-3-Clause
// The updatable spatial index of odometry's local map (docs/design/odometry.md,
// "Odometry"): the cells a change touches get new lists appended to the
// entries (or rewritten in place when they fit the old), and the entries are
// compacted once stale ones outnumber the live.
#include <algorithm>
#include <exception>
#include <stdexcept>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

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

void GaussianIndex::ListingChanges(const std::vector<Gaussian>& gaussians, const std::vector<std::uint32_t>& changed,
                                   const std::vector<std::uint32_t>& removed, std::vector<Listing>& leaving,
                                   std::vector<Listing>& joining) {
  // 1: changed, not yet listed again; 2: done (each id once; changed wins
  // over removed).
  std::vector<char> state(gaussians_.size(), 0);
  for (const std::uint32_t id : changed) state[id] = 1;
  for (const std::uint32_t id : removed) {
    if (id >= state.size() || state[id] != 0) continue;
    state[id] = 2;
    for (const std::int64_t key : listed_cells_[id]) leaving.emplace_back(key, id);
    std::vector<std::int64_t>().swap(listed_cells_[id]);  // frees the capacity (`= {}` keeps it)
  }
  // Each changed Gaussian's cells (apart for each, so side by side; a
  // failure is reported as the first failing one's in `changed`).
  std::vector<std::uint32_t> relisted;
  for (const std::uint32_t id : changed) {
    if (state[id] != 1) continue;
    state[id] = 2;
    relisted.push_back(id);
  }
  std::vector<std::vector<std::int64_t>> cells_of(relisted.size());
  std::vector<std::exception_ptr> failures(relisted.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, relisted.size(), 16), [&](const auto& range) {
    for (std::size_t r = range.begin(); r < range.end(); ++r) {
      try {
        Index(gaussians[relisted[r]], relisted[r], cells_of[r]);
        std::sort(cells_of[r].begin(), cells_of[r].end());
      } catch (...) {
        failures[r] = std::current_exception();
      }
    }
  });
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
  // A changed Gaussian leaves the cells it has moved out of and joins the new
  // ones; the cells it meets before and after keep their lists.
  for (std::size_t r = 0; r < relisted.size(); ++r) {
    const std::uint32_t id = relisted[r];
    const std::vector<std::int64_t>& cells = cells_of[r];
    const std::vector<std::int64_t>& before = listed_cells_[id];
    auto old = before.begin();
    auto now = cells.begin();
    while (old != before.end() || now != cells.end()) {
      if (now == cells.end() || (old != before.end() && *old < *now)) {
        leaving.emplace_back(*old++, id);
      } else if (old == before.end() || *now < *old) {
        joining.emplace_back(*now++, id);
      } else {
        ++old, ++now;
      }
    }
    // A list that shrank gives its memory back.
    std::vector<std::int64_t>& listed = listed_cells_[id];
    if (listed.capacity() > 2 * cells.size() + 8) std::vector<std::int64_t>().swap(listed);
    listed.assign(cells.begin(), cells.end());
  }
  std::sort(leaving.begin(), leaving.end());
  std::sort(joining.begin(), joining.end());
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
  // (cell, id) of every listing that goes and of every one that comes,
  // sorted: each cell's are a run, in id order.
  std::vector<Listing> leaving, joining;
  ListingChanges(gaussians, changed, removed, leaving, joining);
  std::vector<std::int64_t> dirty;
  dirty.reserve(leaving.size() + joining.size());
  for (const Listing& listing : leaving) dirty.push_back(listing.first);
  for (const Listing& listing : joining) dirty.push_back(listing.first);
  std::inplace_merge(dirty.begin(), dirty.begin() + std::ptrdiff_t(leaving.size()), dirty.end());
  dirty.erase(std::unique(dirty.begin(), dirty.end()), dirty.end());
  if (cells_.empty() || 2 * (cell_count_ + dirty.size()) > cells_.size()) Compact(dirty.size());
  // Each touched cell's list: its entries that stay merged with those that
  // join, both in id order as the static index lists them (ties go to the
  // smallest id).
  std::vector<std::uint32_t> staying, joined;
  auto next_join = joining.begin();
  auto next_leave = leaving.begin();
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
        const std::uint32_t id = cell_entries_[e];
        while (next_leave != leaving.end() && next_leave->first == key && next_leave->second < id) ++next_leave;
        if (next_leave != leaving.end() && next_leave->first == key && next_leave->second == id) continue;
        staying.push_back(id);
      }
      stale_entries_ += cell.end - cell.begin;
    } else {
      cell.key = key;
      ++cell_count_;
    }
    while (next_leave != leaving.end() && next_leave->first == key) ++next_leave;
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
