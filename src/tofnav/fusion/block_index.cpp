// SPDX-License-Identifier: BSD-3-Clause
// Internal to TsdfVolume: block ids by packed block key, in a flat open-addressing table.
#include "tofnav/fusion/block_index.hpp"

namespace tofnav {

std::size_t BlockIndex::Home(std::uint64_t key) const {
  // Fibonacci hashing: the top bits of the product depend on every bit of the key (packed keys
  // of neighbouring blocks differ only in low bits of each field).
  constexpr std::uint64_t kGoldenRatio = 0x9E3779B97F4A7C15ull;
  return static_cast<std::size_t>((key * kGoldenRatio) >> shift_);
}

std::size_t BlockIndex::Find(std::uint64_t key) const {
  if (slots_.empty()) return kMissing;
  const std::size_t mask = slots_.size() - 1;
  for (std::size_t s = Home(key);; s = (s + 1) & mask) {
    if (slots_[s].key == key) return static_cast<std::size_t>(slots_[s].id);
    if (slots_[s].key == kEmpty) return kMissing;
  }
}

std::size_t BlockIndex::Insert(std::uint64_t key, std::size_t id) {
  if (2 * (size_ + 1) > slots_.size()) Grow();
  const std::size_t mask = slots_.size() - 1;
  for (std::size_t s = Home(key);; s = (s + 1) & mask) {
    if (slots_[s].key == key) return static_cast<std::size_t>(slots_[s].id);
    if (slots_[s].key == kEmpty) {
      slots_[s] = {key, id};
      ++size_;
      return id;
    }
  }
}

void BlockIndex::Grow() {
  constexpr std::size_t kFirstSlots = 1024;
  std::vector<Slot> old = std::move(slots_);
  const std::size_t slots = old.empty() ? kFirstSlots : 2 * old.size();
  slots_.assign(slots, Slot{kEmpty, 0});
  shift_ = 64 - __builtin_ctzll(slots);
  const std::size_t mask = slots - 1;
  for (const Slot& slot : old) {
    if (slot.key == kEmpty) continue;
    std::size_t s = Home(slot.key);
    while (slots_[s].key != kEmpty) s = (s + 1) & mask;
    slots_[s] = slot;
  }
}

}  // namespace tofnav
