// SPDX-License-Identifier: BSD-3-Clause
// ToolTracker over synthetic frames: statuses, no stale poses, the filters in the world and in
// `ahat` (the world position and partial poses: tool_tracker_world_test.cpp).
#include "tofnav/tracking/tool_tracker.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <random>

#include "matchers.hpp"
#include "tracking_test_tools.hpp"

namespace tofnav {
namespace {

using testing::ReferenceTool;
using testing::SecondTool;
using testing::TurningCamera;

// A tool fixed in the world at 450 mm seen by TurningCamera over 150 frames at 45 Hz, tracked by
// `a` (which must keep a filtered pose) and `b`; `add(a, b, truth)` on the frames after a warm-up
// in which `b` has a filtered pose (a lagging filter may gate a frame of the turning camera).
int RunTurningCamera(
    ToolTracker& a, ToolTracker& b, std::uint64_t seed,
    const std::function<void(const TrackedTool&, const TrackedTool&, const Rigid3d&)>& add,
    const ToolGeometry& tool = ReferenceTool()) {
  constexpr double kMarkerNoiseMm = 0.3;  // per axis, about the raw tilt noise of a small tool
  const Rigid3d world_from_tool = testing::FacingToolPose({0.0, 0.0, 450.0}, 0.3, 0.2);
  std::mt19937_64 rng(seed);
  int n = 0;
  for (int i = 0; i < 150; ++i) {
    const double t = i / 45.0;
    const Rigid3d world_from_ahat = TurningCamera(t);
    const Rigid3d truth = world_from_ahat.Inverse() * world_from_tool;
    const std::vector<DetectedMarker> d = testing::ToolDetections(tool, truth, kMarkerNoiseMm, rng);
    const TrackedTool ta = a.Track(d, t, world_from_ahat).tools[0];
    const TrackedTool tb = b.Track(d, t, world_from_ahat).tools[0];
    EXPECT_TRUE(ta.measurement.ahat_from_tool.has_value()) << i;
    if (i < 30 || !tb.filtered_ahat_from_tool || !ta.measurement.ahat_from_tool) continue;
    EXPECT_TRUE(ta.filtered_ahat_from_tool.has_value()) << i;
    if (!ta.filtered_ahat_from_tool) continue;
    add(ta, tb, truth);
    ++n;
  }
  return n;
}

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

// A tool fixed in the world seen by a camera turning at up to ~30 deg/s (a head-worn display):
// with the camera's world pose the orientation is filtered where the tool stands still, so the
// filter averages the per-frame noise instead of lagging the camera.
TEST(ToolTracker, FiltersTheOrientationInTheWorldWhenTheCameraPoseIsKnown) {
  constexpr double kMaxWorldToRawRatio = 0.6;  // filtered in world vs raw rotation RMS
  ToolTracker in_world({ReferenceTool()});
  ToolTrackerOptions ahat_options;
  ahat_options.rotation_in_world = false;
  ToolTracker in_ahat({ReferenceTool()}, ahat_options);
  double raw2 = 0.0, world2 = 0.0, ahat2 = 0.0;
  const int n = RunTurningCamera(
      in_world, in_ahat, 4, [&](const TrackedTool& a, const TrackedTool& b, const Rigid3d& truth) {
        raw2 += std::pow(RotationDistanceRad(*a.measurement.ahat_from_tool, truth), 2);
        world2 += std::pow(RotationDistanceRad(*a.filtered_ahat_from_tool, truth), 2);
        ahat2 += std::pow(RotationDistanceRad(*b.filtered_ahat_from_tool, truth), 2);
      });
  EXPECT_GE(n, 110);
  EXPECT_LT(std::sqrt(world2 / n), kMaxWorldToRawRatio * std::sqrt(raw2 / n));
  EXPECT_LT(world2, ahat2);
}

// A tool whose origin lies 150 mm from its markers (a headframe's first plate, a pointer's tip):
// the filters hold the pose of the markers' centroid, so the world-filtered orientation turns the
// pose about the markers and the origin gets the filtered tilt times the lever, not the raw one.
// Filtered about the origin instead, the origin kept the raw tilt's lever error (ratio ~1).
TEST(ToolTracker, FiltersAboutTheMarkersSoAFarOriginGetsTheFilteredTilt) {
  constexpr double kMaxFilteredToRawRatio = 0.6;  // origin position RMS, filtered vs raw
  ToolGeometry far_origin = ReferenceTool();
  for (Eigen::Vector3d& m : far_origin.markers_in_tool) m += Eigen::Vector3d(150.0, 0.0, 0.0);
  ToolTracker a({far_origin}), b({far_origin});
  double raw2 = 0.0, filtered2 = 0.0;
  const int n = RunTurningCamera(
      a, b, 5,
      [&](const TrackedTool& t, const TrackedTool&, const Rigid3d& truth) {
        raw2 += (t.measurement.ahat_from_tool->translation - truth.translation).squaredNorm();
        filtered2 += (t.filtered_ahat_from_tool->translation - truth.translation).squaredNorm();
      },
      far_origin);
  EXPECT_GE(n, 110);
  EXPECT_LT(std::sqrt(filtered2 / n), kMaxFilteredToRawRatio * std::sqrt(raw2 / n));
}

// The suite's sparse sessions: a frame every 0.156 s, every third slot dropped (0.31 s gaps,
// beyond the ahat filter's 0.2 s), and a headset whose world position drifts 20 mm/s (SLAM
// drift). The world orientation filter bridges the gaps and ignores the drift, so the held
// orientation averages the tilt noise; with the ahat filter's gap and rate it restarts from
// single raw poses.
TEST(ToolTracker, HoldsTheWorldOrientationAcrossDroppedFramesAndSlamDrift) {
  constexpr double kMaxWorldToRawRatio = 0.7;  // filtered vs raw rotation RMS
  ToolTracker bridged({ReferenceTool()});
  ToolTrackerOptions restarting_options;
  restarting_options.world_max_gap_s = restarting_options.filter.max_gap_s;
  restarting_options.world_rate_sigma_rad_per_s = 1000.0;
  ToolTracker restarting({ReferenceTool()}, restarting_options);
  const Rigid3d world_from_tool = testing::FacingToolPose({0.0, 0.0, 450.0}, 0.3, 0.2);
  std::mt19937_64 rng(9);
  double raw2 = 0.0, bridged2 = 0.0, restarting2 = 0.0;
  int n = 0;
  double t = 0.0;
  for (int i = 0; i < 90; ++i) {
    t += i % 3 == 2 ? 0.311 : 0.156;
    const Rigid3d true_world_from_ahat = TurningCamera(t);
    Rigid3d slam_world_from_ahat = true_world_from_ahat;
    slam_world_from_ahat.translation += Eigen::Vector3d(20.0 * t, 0.0, 0.0);
    const Rigid3d truth = true_world_from_ahat.Inverse() * world_from_tool;
    const std::vector<DetectedMarker> d = testing::ToolDetections(ReferenceTool(), truth, 0.3, rng);
    const TrackedTool a = bridged.Track(d, t, slam_world_from_ahat).tools[0];
    const TrackedTool b = restarting.Track(d, t, slam_world_from_ahat).tools[0];
    if (i < 10 || !a.filtered_ahat_from_tool || !b.filtered_ahat_from_tool) continue;
    raw2 += std::pow(RotationDistanceRad(*a.measurement.ahat_from_tool, truth), 2);
    bridged2 += std::pow(RotationDistanceRad(*a.filtered_ahat_from_tool, truth), 2);
    restarting2 += std::pow(RotationDistanceRad(*b.filtered_ahat_from_tool, truth), 2);
    ++n;
  }
  EXPECT_GE(n, 70);
  RecordProperty("raw_deg", std::to_string(std::sqrt(raw2 / n) * 180.0 / 3.141592653589793));
  RecordProperty("bridged_deg",
                 std::to_string(std::sqrt(bridged2 / n) * 180.0 / 3.141592653589793));
  EXPECT_LT(bridged2, kMaxWorldToRawRatio * kMaxWorldToRawRatio * raw2);
  EXPECT_LT(bridged2, restarting2);
}

// A patient who turns the head: the tool turns in the world at 5 deg/s for 1.5 s between two
// still spells, seen at 45 Hz by the turning camera with 0.5 mm marker noise (raw tilt 0.63 deg
// RMS; the suite's reference plates: 0.46-0.62). The world filter, tuned for a still tool
// (world_rate and world_accel 0.003), averages more frames than the looser 0.01 while the tool
// stands still, and still follows the turn within a bound: the simulator's patients never turn,
// so this is where that tuning's cost is measured (session 30, the orientation noise growing
// with range beyond 430 mm: still, 0.18 against 0.23 deg RMS; turning, 0.85 deg worst. With a
// flat 0.006 rad, tried in session 29, the turn was seen only once its lag crossed the gate's
// 2 deg floor: 2.2 deg worst).
TEST(ToolTracker, FollowsAPatientWhoTurnsTheHeadWhileAveragingAStillTool) {
  constexpr double kMaxTurnErrorDeg = 1.0;        // worst filtered error while and after turning
  constexpr double kMaxStillToLooseRatio = 0.85;  // still spells: RMS against the 0.01 tuning
  constexpr double kDegPerRad = 180.0 / 3.141592653589793;
  constexpr double kTurnRadPerS = 5.0 / kDegPerRad;
  ToolTrackerOptions loose_options;
  loose_options.world_rate_sigma_rad_per_s = 0.01;
  loose_options.world_accel_sigma_rad_per_s2 = 0.01;
  loose_options.world_still_sigma_rad_per_s = 0.0;  // the filter of sessions 13-19
  const Rigid3d start = testing::FacingToolPose({0.0, 0.0, 450.0}, 0.3, 0.2);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, 1.0, 0.2).normalized();
  double tight_still2 = 0.0, loose_still2 = 0.0, raw_still2 = 0.0, worst_turn_deg = 0.0;
  int still = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    ToolTracker tight({ReferenceTool()});
    ToolTracker loose({ReferenceTool()}, loose_options);
    std::mt19937_64 rng(seed);
    for (int i = 0; i < 270; ++i) {  // 2 s still, 1.5 s turning, 2.5 s still
      const double t = i / 45.0;
      const double angle = kTurnRadPerS * std::clamp(t - 2.0, 0.0, 1.5);
      const Rigid3d world_from_tool(
          Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis)) * start.rotation, start.translation);
      const Rigid3d world_from_ahat = TurningCamera(t);
      const Rigid3d truth = world_from_ahat.Inverse() * world_from_tool;
      const std::vector<DetectedMarker> d =
          testing::ToolDetections(ReferenceTool(), truth, 0.5, rng);
      const TrackedTool a = tight.Track(d, t, world_from_ahat).tools[0];
      const TrackedTool b = loose.Track(d, t, world_from_ahat).tools[0];
      // Skip the warm-up and the frames whose `ahat` filter gated (no filtered pose in either).
      if (i < 30 || !a.filtered_ahat_from_tool || !b.filtered_ahat_from_tool) continue;
      const double error_deg = RotationDistanceRad(*a.filtered_ahat_from_tool, truth) * kDegPerRad;
      if (t >= 2.0) worst_turn_deg = std::max(worst_turn_deg, error_deg);
      if (t >= 2.0 && t <= 4.5) continue;
      tight_still2 += error_deg * error_deg;
      loose_still2 +=
          std::pow(RotationDistanceRad(*b.filtered_ahat_from_tool, truth) * kDegPerRad, 2);
      raw_still2 +=
          std::pow(RotationDistanceRad(*a.measurement.ahat_from_tool, truth) * kDegPerRad, 2);
      ++still;
    }
  }
  EXPECT_GE(still, 6 * 100);
  RecordProperty("raw_still_deg", std::to_string(std::sqrt(raw_still2 / still)));
  RecordProperty("tight_still_deg", std::to_string(std::sqrt(tight_still2 / still)));
  RecordProperty("loose_still_deg", std::to_string(std::sqrt(loose_still2 / still)));
  RecordProperty("worst_turn_deg", std::to_string(worst_turn_deg));
  EXPECT_LT(tight_still2, kMaxStillToLooseRatio * kMaxStillToLooseRatio * loose_still2);
  EXPECT_LT(worst_turn_deg, kMaxTurnErrorDeg);
}

// The same world-fixed tool: its position in `ahat` moves with the camera at up to ~250 mm/s.
// The camera's motion raises the position filter's process noise, so the filtered position
// follows the camera (below the raw error) instead of lagging it (above, with the static tuning).
TEST(ToolTracker, FollowsAWorldFixedToolWithTheCamerasMotion) {
  ToolTrackerOptions adaptive_options;
  adaptive_options.position_in_world = false;  // the `ahat` filter's position alone
  ToolTracker adaptive({ReferenceTool()}, adaptive_options);
  ToolTrackerOptions static_options = adaptive_options;
  static_options.camera_motion_bandwidth_per_s = 0.0;
  ToolTracker static_tuned({ReferenceTool()}, static_options);
  double raw2 = 0.0, adaptive2 = 0.0, static2 = 0.0;
  const int n = RunTurningCamera(
      adaptive, static_tuned, 5,
      [&](const TrackedTool& a, const TrackedTool& b, const Rigid3d& truth) {
        raw2 += (a.measurement.ahat_from_tool->translation - truth.translation).squaredNorm();
        adaptive2 += (a.filtered_ahat_from_tool->translation - truth.translation).squaredNorm();
        static2 += (b.filtered_ahat_from_tool->translation - truth.translation).squaredNorm();
      });
  EXPECT_GE(n, 110);
  EXPECT_LT(adaptive2, raw2);
  EXPECT_GT(static2, raw2);
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
