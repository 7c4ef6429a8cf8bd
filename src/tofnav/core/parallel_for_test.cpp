// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/core/parallel_for.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace tofnav {
namespace {

TEST(ParallelFor, VisitsEveryIndexOnce) {
  std::vector<int> visits(10007, 0);
  ParallelFor(
      0, static_cast<std::int64_t>(visits.size()),
      [&](std::int64_t i) { ++visits[static_cast<std::size_t>(i)]; }, 64);
  for (int v : visits) ASSERT_EQ(v, 1);
}

TEST(ParallelFor, EmptyRangeDoesNothing) {
  int calls = 0;
  ParallelFor(5, 5, [&](std::int64_t) { ++calls; });
  ParallelFor(5, 2, [&](std::int64_t) { ++calls; });
  EXPECT_EQ(calls, 0);
}

}  // namespace
}  // namespace tofnav
