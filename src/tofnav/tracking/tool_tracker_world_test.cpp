// SPDX-License-Identifier: BSD-3-Clause
// ToolTracker's world filters: a world-fixed tool's position fused with the rig pose, and a
// partial pose after a look-away (docs/tracking.md 1).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "matchers.hpp"
#include "tofnav/sim/timing.hpp"
#include "tofnav/tracking/tool_tracker.hpp"
#include "tracking_test_tools.hpp"

namespace tofnav {
namespace {

using testing::ReferenceTool;
using testing::TurningCamera;

// The same world-fixed tool, with a rig pose that errs by 0.3 mm and 3e-4 rad per axis and frame
// (the simulator's SLAM jitter) and markers whose centres err by 0.73 mm along the view ray and
// 0.22 mm across it (a plate at 700 mm, its centroid 0.37 / 0.11 mm: WorldPositionOptions): the
// position held in the world and predicted through each frame's rig pose, fused with the
// measurement, beats the `ahat` filter's (which follows the turning camera, so it is about the raw
// pose). At best (known jitter, converged) a ratio of 0.70.
TEST(ToolTracker, FusesAWorldFixedToolsPositionWithTheRigPose) {
  constexpr double kMaxWorldToAhatRatio = 0.85;  // position RMS, fused vs `ahat` filter alone
  ToolTracker fused({ReferenceTool()});
  ToolTrackerOptions ahat_options;
  ahat_options.position_in_world = false;
  ToolTracker ahat_only({ReferenceTool()}, ahat_options);
  const Rigid3d world_from_tool = testing::FacingToolPose({0.0, 0.0, 700.0}, 0.3, 0.2);
  std::mt19937_64 rng(11);
  double fused2 = 0.0, ahat2 = 0.0;
  int n = 0;
  for (int i = 0; i < 300; ++i) {
    const double t = i / 45.0;
    const Rigid3d true_world_from_ahat = TurningCamera(t);
    const Rigid3d reported = sim::JitterPose(true_world_from_ahat, {}, rng);  // 0.3 mm, 3e-4 rad
    const Rigid3d truth = true_world_from_ahat.Inverse() * world_from_tool;
    const std::vector<DetectedMarker> d =
        testing::RayNoiseDetections(ReferenceTool(), truth, 0.73, 0.22, rng);
    const TrackedTool a = fused.Track(d, t, reported).tools[0];
    const TrackedTool b = ahat_only.Track(d, t, reported).tools[0];
    if (i < 30 || !a.filtered_ahat_from_tool || !b.filtered_ahat_from_tool) continue;
    fused2 += (a.filtered_ahat_from_tool->translation - truth.translation).squaredNorm();
    ahat2 += (b.filtered_ahat_from_tool->translation - truth.translation).squaredNorm();
    ++n;
  }
  EXPECT_GE(n, 250);
  RecordProperty("fused_mm", std::to_string(std::sqrt(fused2 / n)));
  RecordProperty("ahat_mm", std::to_string(std::sqrt(ahat2 / n)));
  EXPECT_LT(fused2, kMaxWorldToAhatRatio * kMaxWorldToAhatRatio * ahat2);
}

// After a 2.3 s look-away the first pose back is matched on three of the four markers and is
// tilted by 2.7 deg about them (the missing marker sits at an occluder's edge, which clips the
// others: spent suite sets 16-17 hold such poses, 3-of-4 poses erring 2.2 times as much as whole
// ones, docs/tracking.md 1). The held world orientation has grown uncertain over the gap, so
// counted as a whole pose it pulls the output most of the way (and the good poses after it are
// gated until a restart); counted for a fifth (partial_variance_scale), the output moves by less
// than half the tilt and is back within 0.5 deg on the next frame (1.04 then 0.37 deg, against
// 2.07 then 1.20 counted whole: the figures of spent set 17's mr-device-a-jitter, 2.06 then
// 2.25, 2.63, were the same event).
TEST(ToolTracker, APartialPoseAfterALookAwayTiltsTheHeldOrientationLess) {
  constexpr double kTiltRad = 2.7 * std::numbers::pi / 180.0;
  const auto run = [&](double partial_variance_scale) {
    ToolTrackerOptions options;
    options.partial_variance_scale = partial_variance_scale;
    ToolTracker tracker({ReferenceTool()}, options);
    const Rigid3d world_from_tool = testing::FacingToolPose({0.0, 0.0, 600.0}, 0.3, 0.2);
    const Points3d& markers = ReferenceTool().markers_in_tool;
    const Eigen::Vector3d centre = (markers[0] + markers[1] + markers[2]) / 3.0;
    const Rigid3d tilt(Eigen::Quaterniond(Eigen::AngleAxisd(kTiltRad, Eigen::Vector3d::UnitX())),
                       centre - Eigen::AngleAxisd(kTiltRad, Eigen::Vector3d::UnitX()) * centre);
    std::mt19937_64 rng(5);
    std::vector<double> after_deg;
    for (int i = 0; i < 60; ++i) {
      if (i >= 40 && i < 55) continue;  // looking away for 15 frames (2.3 s)
      const double t = 0.156 * i;
      const Rigid3d world_from_ahat = TurningCamera(t);
      const Rigid3d truth = world_from_ahat.Inverse() * world_from_tool;
      std::vector<DetectedMarker> d =
          testing::ToolDetections(ReferenceTool(), i == 55 ? truth * tilt : truth, 0.1, rng);
      if (i == 55) d.pop_back();  // marker 3 hidden
      const TrackedTool tracked = tracker.Track(d, t, world_from_ahat).tools[0];
      if (i == 55) {
        EXPECT_EQ(tracked.measurement.status, ToolStatus::kPartiallyOccluded);
        EXPECT_GT(RotationDistanceRad(*tracked.measurement.ahat_from_tool, truth), 0.9 * kTiltRad);
      }
      if (i >= 55) {
        after_deg.push_back(tracked.filtered_ahat_from_tool
                                ? RotationDistanceRad(*tracked.filtered_ahat_from_tool, truth) *
                                      180.0 / std::numbers::pi
                                : 90.0);  // no output counts as lost
      }
    }
    return after_deg;
  };
  const std::vector<double> fifth = run(ToolTrackerOptions{}.partial_variance_scale);
  const std::vector<double> whole = run(1.0);
  ASSERT_EQ(fifth.size(), 5u);
  for (std::size_t k = 0; k < fifth.size(); ++k) {
    std::printf("frame %zu after the partial pose: filtered error %.2f deg (counted whole: %.2f)\n",
                k, fifth[k], whole[k]);
  }
  EXPECT_LT(fifth[0], 0.5 * 2.7);
  EXPECT_LT(fifth[1], 0.5);
  EXPECT_GT(whole[0], fifth[0]);
  EXPECT_GT(whole[1], fifth[1]);
}

// A plate first seen at 650 mm: its filtered_rotation_sd_rad starts at one frame's fit (sqrt(3)
// times the fit's per-axis sd, a whole pose fitting as its noise model says) and shrinks as the
// still plate is averaged; after a 2 s look-away the first pose back keeps the held orientation's,
// far below a first frame's (docs/tracking.md 1, "A pose that is still settling").
TEST(ToolTracker, TheFilteredOrientationsSdShrinksAsAStillToolIsAveraged) {
  ToolTracker tracker({ReferenceTool()});
  const Rigid3d world_from_tool = testing::FacingToolPose({0.0, 0.0, 650.0}, 0.3, 0.2);
  std::mt19937_64 rng(7);
  std::vector<double> sd_rad, fit_sd_rad;
  for (int i = 0; i < 60; ++i) {
    if (i >= 30 && i < 43) continue;  // looking away for 13 frames (2 s)
    const double t = 0.156 * i;
    const Rigid3d world_from_ahat = TurningCamera(t);
    const Rigid3d truth = world_from_ahat.Inverse() * world_from_tool;
    const TrackedTool tracked =
        tracker
            .Track(testing::RayNoiseDetections(ReferenceTool(), truth, 0.5, 0.15, rng), t,
                   world_from_ahat)
            .tools[0];
    // Present with every filtered pose (a gated frame has neither).
    EXPECT_EQ(tracked.filtered_rotation_sd_rad.has_value(),
              tracked.filtered_ahat_from_tool.has_value())
        << "frame " << i;
    sd_rad.push_back(tracked.filtered_rotation_sd_rad.value_or(std::nan("")));
    fit_sd_rad.push_back(tracked.measurement.rotation_sd_rad);
  }
  ASSERT_EQ(sd_rad.size(), 47u);
  for (const std::size_t k : {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 29, 30}) {
    ASSERT_FALSE(std::isnan(sd_rad[k])) << "frame " << k;
  }
  EXPECT_GT(fit_sd_rad[0], 0.0);
  EXPECT_GE(sd_rad[0], std::sqrt(3.0) * fit_sd_rad[0] * (1.0 - 1e-12));  // one frame's, or more
  for (std::size_t k = 1; k < 10; ++k) {
    EXPECT_LT(sd_rad[k] / fit_sd_rad[k], sd_rad[k - 1] / fit_sd_rad[k - 1]) << "frame " << k;
  }
  EXPECT_LT(sd_rad[29] / fit_sd_rad[29], 0.35 * std::sqrt(3.0));  // under 1/8 of one's variance
  EXPECT_LT(sd_rad[30] / fit_sd_rad[30], 0.5 * std::sqrt(3.0));   // the first frame back
}

}  // namespace
}  // namespace tofnav
