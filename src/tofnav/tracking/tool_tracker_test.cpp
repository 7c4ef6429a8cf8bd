// SPDX-License-Identifier: BSD-3-Clause
// ToolTracker over synthetic frames: statuses, no stale poses, re-acquisition without swim-in.
#include "tofnav/tracking/tool_tracker.hpp"

#include <gtest/gtest.h>

#include <random>

#include "matchers.hpp"
#include "tracking_test_tools.hpp"

namespace tofnav {
namespace {

using testing::ReferenceTool;
using testing::SecondTool;

TEST(ToolTracker, TracksTwoToolsAndNeverReportsAStalePose) {
  std::mt19937_64 rng(1);
  ToolTracker tracker({ReferenceTool(), SecondTool()});
  double t = 0.0;
  for (int i = 0; i < 60; ++i) {
    t += i % 7 == 0 ? 0.15 : 1.0 / 45.0;  // irregular rate
    const Rigid3d a = testing::FacingToolPose({-80.0 + 40.0 * t, 0.0, 450.0}, 0.2, 0.3 * t);
    const Rigid3d b = testing::FacingToolPose({100.0, 20.0, 500.0 - 30.0 * t}, -0.3);
    const bool b_hidden = i >= 20 && i < 35;  // the second tool leaves the view
    std::vector<DetectedMarker> d = testing::ToolDetections(ReferenceTool(), a, 0.1, rng);
    if (!b_hidden) {
      const std::vector<DetectedMarker> db = testing::ToolDetections(SecondTool(), b, 0.1, rng);
      d.insert(d.end(), db.begin(), db.end());
    }
    testing::AddSpurious(d, 3, rng, {0, 0, 800}, 100.0);
    const TrackingFrame f = tracker.Track(d, t);
    ASSERT_EQ(f.tools.size(), 2u);
    ASSERT_EQ(f.tools[0].status(), ToolStatus::kOk) << i;
    EXPECT_THAT(*f.tools[0].measurement.ahat_from_tool, RigidNear(a, 0.01, 0.4));
    ASSERT_TRUE(f.tools[0].filtered_ahat_from_tool.has_value());
    EXPECT_THAT(*f.tools[0].filtered_ahat_from_tool, RigidNear(a, 0.02, 1.0));
    if (b_hidden) {
      EXPECT_NE(f.tools[1].status(), ToolStatus::kOk);
      EXPECT_FALSE(f.tools[1].measurement.ahat_from_tool.has_value());
      EXPECT_FALSE(f.tools[1].filtered_ahat_from_tool.has_value());
    } else {
      ASSERT_EQ(f.tools[1].status(), ToolStatus::kOk) << i;
      EXPECT_EQ(f.tools[1].filter_reset, i == 0 || i == 35);  // re-acquired: no swim-in
      if (i == 35) {
        EXPECT_THAT(*f.tools[1].filtered_ahat_from_tool,
                    RigidNear(*f.tools[1].measurement.ahat_from_tool, 1e-12, 1e-12));
      }
    }
  }
}

TEST(ToolTracker, RejectsInvalidToolsAndWorksWithoutFilter) {
  ToolGeometry duplicate = ReferenceTool();
  duplicate.markers_in_tool[3] = duplicate.markers_in_tool[0];
  EXPECT_THROW(ToolTracker({duplicate}), std::invalid_argument);
  ToolTrackerOptions options;
  options.filter_enabled = false;
  ToolTracker tracker({ReferenceTool()}, options);
  std::mt19937_64 rng(2);
  const TrackingFrame f = tracker.Track(
      testing::ToolDetections(ReferenceTool(), testing::FacingToolPose({0, 0, 400}), 0.1, rng),
      0.0);
  EXPECT_EQ(f.tools[0].status(), ToolStatus::kOk);
  EXPECT_FALSE(f.tools[0].filtered_ahat_from_tool.has_value());
  EXPECT_EQ(tracker.Track({}, 0.1).tools[0].status(), ToolStatus::kTooFewMarkers);
}

}  // namespace
}  // namespace tofnav
