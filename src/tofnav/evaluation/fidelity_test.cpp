// SPDX-License-Identifier: BSD-3-Clause
// The fidelity rows' bands: a published spread, or +-25 % of a figure published without one;
// the experiments' order.
#include "tofnav/evaluation/fidelity.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace tofnav {
namespace {

TEST(FidelityRow, APublishedSpreadIsTheBand) {
  const FidelityRow r = MakeFidelityRow("skin study", "mean", "paper", 7.58, 1.49, 6.0);
  EXPECT_TRUE(r.spread_published);
  EXPECT_DOUBLE_EQ(r.published_low, 7.58 - 1.49);
  EXPECT_DOUBLE_EQ(r.published_high, 7.58 + 1.49);
  EXPECT_FALSE(r.within());  // 6.0 < 6.09
  EXPECT_TRUE(MakeFidelityRow("a", "b", "c", 7.58, 1.49, 6.1).within());
  EXPECT_TRUE(MakeFidelityRow("a", "b", "c", 7.58, 1.49, 9.07).within());
}

TEST(FidelityRow, WithoutASpreadTheBandIsAQuarterEitherSide) {
  const FidelityRow r = MakeFidelityRow("tape", "change", "paper", 4.0, std::nullopt, 5.0);
  EXPECT_FALSE(r.spread_published);
  EXPECT_DOUBLE_EQ(r.published_low, 3.0);
  EXPECT_DOUBLE_EQ(r.published_high, 5.0);
  EXPECT_TRUE(r.within());
  EXPECT_FALSE(MakeFidelityRow("a", "b", "c", 4.0, std::nullopt, 5.01).within());
  EXPECT_FALSE(MakeFidelityRow("a", "b", "c", 4.0, std::nullopt, std::nan("")).within());
}

TEST(FidelityExperiments, TheMarkersRunAfterTheTapeWhoseFrfTheyUse) {
  const std::vector<std::string>& names = FidelityExperiments();
  const auto tape = std::find(names.begin(), names.end(), "tape");
  const auto markers = std::find(names.begin(), names.end(), "markers");
  ASSERT_NE(markers, names.end());
  EXPECT_LT(tape, markers);
}

}  // namespace
}  // namespace tofnav
