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

TEST(FidelityPhantoms, TableIAfterCorrectsEveryFrameByTheGivenModel) {
  // A model that only subtracts C1 moves every pixel's mean by exactly C1: after its correction
  // the head's median is the one before it on the same pixels minus C1, with the same spread, up
  // to float rounding of the corrected image.
  constexpr double kC1Mm = 5.0, kTolMm = 1e-3;
  FidelityOptions options;
  options.out = std::filesystem::path(::testing::TempDir()) / "fidelity_phantoms_after";
  options.frames_scale = 0.05;  // 5 frames per phantom
  options.only = {"phantoms"};
  DepthModelFile model;
  model.model.c1_mm = kC1Mm;
  options.phantom_depth_models["nylon"] = model;
  const FidelityResult result = RunFidelity(options);
  ASSERT_EQ(result.rows.size(), 6u);  // photopolymer before (2), nylon before (2) and after (2)
  EXPECT_EQ(result.rows[2].experiment, "Table I, before");
  const FidelityRow& after = result.rows[4];
  EXPECT_EQ(after.experiment, "Table I, after");
  EXPECT_EQ(after.published, 1.08);  // the paper's nylon head after correction
  const nlohmann::ordered_json& kept = result.details.at("phantoms").at(1).at("after");
  EXPECT_NEAR(after.ours, kept.at("before_median_mm").get<double>() - kC1Mm, kTolMm);
  EXPECT_NEAR(result.rows[5].ours, kept.at("before_iqr_mm").get<double>(), kTolMm);
}

}  // namespace
}  // namespace tofnav
