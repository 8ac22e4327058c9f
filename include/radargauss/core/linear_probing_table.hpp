// SPDX-License-Identifier: BSD-3-Clause
// The one hash table of the map code: open addressing with linear probing,
// power-of-two slots at most half full and Fibonacci hashing (the product's
// top bits mix every bit of the hash), so a lookup reads one or two
// adjacent slots. The spatial index's cells and the voxel downsampling's
// voxels are its entries; an entry type says itself which slots are free.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace radargauss {

template <typename Entry>
class LinearProbingTable {
 public:
  // Room for `count` entries, every slot `empty`.
  void Reset(std::size_t count, const Entry& empty) {
    std::size_t slots = 2;
    for (shift_ = 63; slots < 2 * count; --shift_) slots *= 2;
    slots_.assign(slots, empty);
  }
  bool empty() const { return slots_.empty(); }
  std::size_t size() const { return slots_.size(); }  // slots, free ones included

  // The slot where the probe for `hash` starts.
  std::size_t HomeSlot(std::uint64_t hash) const { return std::size_t((hash * 0x9E3779B97F4A7C15ull) >> shift_); }
  // The first slot from HomeSlot(hash) whose entry `found` accepts: the
  // entry sought, or the free slot where it would go.
  template <typename Found>
  std::size_t Probe(std::uint64_t hash, Found&& found) const {
    const std::size_t mask = slots_.size() - 1;
    std::size_t slot = HomeSlot(hash);
    while (!found(slots_[slot])) slot = (slot + 1) & mask;
    return slot;
  }
  Entry& operator[](std::size_t slot) { return slots_[slot]; }
  const Entry& operator[](std::size_t slot) const { return slots_[slot]; }

 private:
  std::vector<Entry> slots_;
  int shift_ = 64;  // 64 - log2(slots)
};

}  // namespace radargauss
