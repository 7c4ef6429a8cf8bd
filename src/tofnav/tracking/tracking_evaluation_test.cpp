// SPDX-License-Identifier: BSD-3-Clause
// Tracking evaluation figures against hand-computed values.
#include "tofnav/tracking/tracking_evaluation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace tofnav {
namespace {

constexpr double kTol = 1e-9;  // exact arithmetic up to rounding [mm, deg]

Rigid3d At(double x, double y, double z) {
  return {Eigen::Quaterniond::Identity(), Eigen::Vector3d(x, y, z)};
}

TEST(TrackingEvaluation, ErrorsFractionAndWrongIdentities) {
  std::vector<ToolEvaluationFrame> frames;
  for (int i = 0; i < 4; ++i) {  // moving truth: no static run
    ToolEvaluationFrame f;
    f.true_ahat_from_tool = At(10.0 * i, 0, 400);
    f.raw = At(10.0 * i + 0.1 * (i + 1), 0, 400);  // errors 0.1, 0.2, 0.3, 0.4 mm
    frames.push_back(f);
  }
  frames[3].raw->rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitX()));
  ToolEvaluationFrame wrong;  // a flipped pose: a wrong identity
  wrong.true_ahat_from_tool = At(50, 0, 400);
  wrong.raw = Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(3.0, Eigen::Vector3d::UnitZ())),
                      Eigen::Vector3d(50, 0, 400));
  frames.push_back(wrong);
  ToolEvaluationFrame missed;
  missed.true_ahat_from_tool = At(60, 0, 400);
  frames.push_back(missed);
  ToolEvaluationFrame occluded;  // not fully visible, not tracked: outside the fraction
  occluded.true_ahat_from_tool = At(70, 0, 400);
  occluded.fully_visible = false;
  frames.push_back(occluded);

  const ToolEvaluation e = EvaluateToolTracking(frames, {});
  EXPECT_EQ(e.frames, 7);
  EXPECT_EQ(e.posed_frames, 5);
  EXPECT_EQ(e.wrong_identities, 1);
  EXPECT_EQ(e.fully_visible_frames, 6);
  EXPECT_EQ(e.tracked_fully_visible, 4);
  EXPECT_NEAR(e.tracked_fraction, 4.0 / 6.0, kTol);
  EXPECT_EQ(e.raw.position_mm.count, 4u);
  EXPECT_NEAR(e.raw.position_mm.median, 0.25, kTol);
  EXPECT_NEAR(e.raw.position_mm.rms, std::sqrt((0.01 + 0.04 + 0.09 + 0.16) / 4.0), kTol);
  EXPECT_NEAR(e.raw.position_mm.max, 0.4, kTol);
  EXPECT_NEAR(e.raw.rotation_deg.max, 0.01 * 180.0 / std::numbers::pi, 1e-7);
  EXPECT_EQ(e.filtered.position_mm.count, 0u);
  EXPECT_EQ(e.raw_fully_visible.position_mm.count, 4u);
  EXPECT_FALSE(e.jitter_raw_mm.has_value());
}

TEST(TrackingEvaluation, StaticJitterAfterWarmUpAndRangeBias) {
  TrackingEvaluationOptions options;
  options.jitter_warmup_frames = 2;
  options.min_static_frames = 4;
  std::vector<ToolEvaluationFrame> frames;
  for (int i = 0; i < 8; ++i) {  // static at z = 450; raw alternates +-0.1 mm in x after warm-up
    ToolEvaluationFrame f;
    f.true_ahat_from_tool = At(0, 0, 450);
    f.raw = At(i < 2 ? 15.0 : (i % 2 == 0 ? 0.1 : -0.1), 0, 450.5);
    f.filtered = At(0, 0, 450);
    frames.push_back(f);
  }
  frames[0].raw = At(2.5, 0, 450);  // warm-up frames may be far off: they do not count
  const Eigen::Vector3d markers[] = {{0, 0, 0}};
  const ToolEvaluation e = EvaluateToolTracking(frames, markers, options);
  ASSERT_TRUE(e.jitter_raw_mm.has_value());
  EXPECT_NEAR(*e.jitter_raw_mm, 0.1, kTol);  // 6 frames at +-0.1 about 0 in x; z constant
  EXPECT_NEAR(*e.jitter_filtered_mm, 0.0, kTol);
  EXPECT_EQ(e.static_frames, 6);
  ASSERT_EQ(e.range_bias.size(), 1u);
  EXPECT_EQ(e.range_bias[0].from_mm, 400.0);
  EXPECT_EQ(e.range_bias[0].count, 7);  // frame 1 (15 mm off) is a wrong identity
  EXPECT_EQ(e.wrong_identities, 1);
}

// Filtered poses reported SETTLING (sd above 0.35 deg) stay in the filtered figures and leave the
// settled ones; a pose without an sd makes no claim and counts as settled.
TEST(TrackingEvaluation, SettledFiguresLeaveOutTheSettlingPoses) {
  std::vector<ToolEvaluationFrame> frames;
  const double sd_deg[] = {0.9, 0.5, 0.3, 0.2, -1.0};  // -1: none reported
  for (int i = 0; i < 5; ++i) {
    ToolEvaluationFrame f;
    f.true_ahat_from_tool = At(10.0 * i, 0, 400);
    f.raw = At(10.0 * i, 0, 400);
    f.filtered = At(10.0 * i + 0.1 * (5 - i), 0, 400);  // errors 0.5, 0.4, 0.3, 0.2, 0.1 mm
    if (sd_deg[i] > 0.0) f.filtered_rotation_sd_rad = sd_deg[i] * std::numbers::pi / 180.0;
    frames.push_back(f);
  }
  const ToolEvaluation e = EvaluateToolTracking(frames, {});
  EXPECT_EQ(e.settling_frames, 2);
  EXPECT_EQ(e.filtered_fully_visible.position_mm.count, 5u);
  EXPECT_EQ(e.filtered_settled_fully_visible.position_mm.count, 3u);
  EXPECT_NEAR(e.filtered_settled_fully_visible.position_mm.rms,
              std::sqrt((0.09 + 0.04 + 0.01) / 3.0), kTol);
  TrackingEvaluationOptions none;
  none.settled_rotation_sd_rad = 1.0;  // nothing settling
  EXPECT_EQ(EvaluateToolTracking(frames, {}, none).settling_frames, 0);
}

TEST(TrackingEvaluation, RejectsBadOptions) {
  TrackingEvaluationOptions options;
  options.wrong_translation_mm = 0.0;
  EXPECT_THROW(EvaluateToolTracking({}, {}, options), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
