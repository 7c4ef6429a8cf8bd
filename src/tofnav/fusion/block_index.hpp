// SPDX-License-Identifier: BSD-3-Clause
// Internal to TsdfVolume: block ids by packed block key, in a flat open-addressing table.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tofnav {

/// Block ids by packed key (63 bits). Linear probing over one array of (key, id) slots kept at
/// most half full: a lookup is a multiply and mostly one cache line, where std::unordered_map
/// follows a pointer to a separately allocated node, a likely cache miss for each of the ~2000
/// blocks a frame touches.
class BlockIndex {
 public:
  static constexpr std::size_t kMissing = ~std::size_t{0};

  /// The id stored for `key`, or kMissing.
  std::size_t Find(std::uint64_t key) const;
  /// Stores `id` for `key` unless the key is present; returns the key's id either way.
  std::size_t Insert(std::uint64_t key, std::size_t id);
  std::size_t size() const { return size_; }

 private:
  struct Slot {
    std::uint64_t key;
    std::uint64_t id;
  };
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // never a packed key (63 bits)

  std::size_t Home(std::uint64_t key) const;  // first slot to probe
  void Grow();

  std::vector<Slot> slots_;  // size a power of two, or empty
  int shift_ = 64;           // 64 - log2(slots_.size())
  std::size_t size_ = 0;
};

}  // namespace tofnav
