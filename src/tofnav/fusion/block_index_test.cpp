// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/fusion/block_index.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <unordered_map>

namespace tofnav {
namespace {

TEST(BlockIndex, FindsEveryInsertedKeyThroughGrowth) {
  // Random 63-bit keys and a dense cube of neighbouring packed keys (21 bits per axis), enough
  // to grow the table several times; checked against std::unordered_map.
  BlockIndex index;
  std::unordered_map<std::uint64_t, std::size_t> truth;
  std::mt19937_64 rng(3);
  const auto add = [&](std::uint64_t key) {
    const std::size_t id = index.Insert(key, truth.size());
    const auto [it, inserted] = truth.try_emplace(key, truth.size());
    ASSERT_EQ(id, it->second) << key;
  };
  for (int i = 0; i < 3000; ++i) add(rng() >> 1);
  for (std::uint64_t x = 0; x < 12; ++x) {
    for (std::uint64_t y = 0; y < 12; ++y) {
      for (std::uint64_t z = 0; z < 12; ++z) add((x + 1000) << 42 | (y + 2000) << 21 | (z + 5));
    }
  }
  add(truth.begin()->first);  // a repeat keeps its id
  EXPECT_EQ(index.size(), truth.size());
  for (const auto& [key, id] : truth) ASSERT_EQ(index.Find(key), id) << key;
  int missing = 0;
  for (int i = 0; i < 3000; ++i) {
    const std::uint64_t key = rng() >> 1;
    if (!truth.contains(key)) missing += index.Find(key) == BlockIndex::kMissing ? 1 : 0;
  }
  EXPECT_EQ(missing, 3000);
  EXPECT_EQ(BlockIndex().Find(42), BlockIndex::kMissing);
}

}  // namespace
}  // namespace tofnav
