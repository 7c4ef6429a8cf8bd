// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/core/frame_batches.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <vector>

namespace tofnav {
namespace {

struct Item {
  std::size_t read_at = 0;
  std::size_t squared = 0;
};

TEST(ForEachInBatches, ReadsAndConsumesInOrderAndPreparesEveryItemOnce) {
  // 37 positions in batches of 8: the last batch is partial; order must hold across batches.
  constexpr std::size_t kCount = 37;
  std::vector<std::size_t> read_order, consume_order, prepared(kCount, 0);
  BatchTimes times;
  ForEachInBatches<Item>(
      kCount, 8,
      [&](std::size_t p) {
        read_order.push_back(p);
        return Item{p, 0};
      },
      [&](Item& item, std::size_t p) {
        item.squared = p * p;
        ++prepared[p];  // each position owns its slot
      },
      [&](Item& item, std::size_t p) {
        EXPECT_EQ(item.read_at, p);
        EXPECT_EQ(item.squared, p * p);
        consume_order.push_back(p);
      },
      &times);
  ASSERT_EQ(read_order.size(), kCount);
  ASSERT_EQ(consume_order.size(), kCount);
  for (std::size_t p = 0; p < kCount; ++p) {
    EXPECT_EQ(read_order[p], p);
    EXPECT_EQ(consume_order[p], p);
    EXPECT_EQ(prepared[p], 1u);
  }
  EXPECT_GE(times.read_s, 0.0);
}

TEST(ForEachInBatches, NothingToDoAndAZeroBatchSizeAreSafe) {
  int calls = 0;
  ForEachInBatches<Item>(
      0, 8, [&](std::size_t) { return Item{}; }, [&](Item&, std::size_t) { ++calls; },
      [&](Item&, std::size_t) { ++calls; });
  EXPECT_EQ(calls, 0);
  ForEachInBatches<Item>(
      3, 0, [&](std::size_t) { return Item{}; }, [&](Item&, std::size_t) {},
      [&](Item&, std::size_t) { ++calls; });
  EXPECT_EQ(calls, 3);  // a batch size of 0 is taken as 1
}

}  // namespace
}  // namespace tofnav
