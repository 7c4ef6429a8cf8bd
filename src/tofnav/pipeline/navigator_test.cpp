// SPDX-License-Identifier: BSD-3-Clause
// Navigator: Eq. (8) against analytic transforms, staleness, guidance quantities.
#include "tofnav/pipeline/navigator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "matchers.hpp"
#include "tofnav/core/units.hpp"

namespace tofnav {
namespace {

constexpr double kExactMm = 1e-9, kExactRad = 1e-9;  // double arithmetic on analytic poses

Rigid3d Turn(double angle_rad, const Eigen::Vector3d& axis, const Eigen::Vector3d& t) {
  return {Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, axis.normalized())), t};
}

const AhatCamera& Camera() {
  static const AhatCamera camera = [] {
    SyntheticAhatOptions o;
    o.rig_from_ahat = TypicalRigFromAhat();
    return AhatCamera(MakeSyntheticAhatCalibration(o));
  }();
  return camera;
}

ToolGeometry Tool(const std::string& name, double scale) {
  ToolGeometry t;
  t.name = name;
  t.markers_in_tool = {{0, 0, 0}, {50 * scale, 0, 0}, {0, 70 * scale, 0}, {30, 40, 20 * scale}};
  return t;
}

NavigationCase Case(bool with_instrument) {
  NavigationCase c;
  c.reference = Tool("Reference", 1.0);
  c.tool_from_image = Turn(0.7, {1, 2, 3}, {10, -40, 120});
  c.plan = {{"right-1", {30, -80, 40}, {20, -30, 10}}, {"left-1", {-30, -80, 40}, {-20, -30, 10}}};
  if (with_instrument) {
    c.instrument = Tool("Drill", 1.4);
    c.instrument->tip_in_tool = Eigen::Vector3d(0, 0, 150);
  }
  return c;
}

/// A tracking frame with the given measured poses (nullopt: tool not seen).
TrackingFrame Tracked(double t_s, std::optional<Rigid3d> reference,
                      std::optional<Rigid3d> instrument = std::nullopt) {
  TrackingFrame f;
  f.timestamp_s = t_s;
  for (const auto& pose : {reference, instrument}) {
    TrackedTool tool;
    tool.measurement.status = pose ? ToolStatus::kOk : ToolStatus::kOutOfView;
    tool.measurement.ahat_from_tool = pose;
    tool.filtered_ahat_from_tool = pose;
    f.tools.push_back(tool);
  }
  return f;
}

TEST(Navigator, PoseChainIsEquationEight) {
  Navigator nav(Camera(), Case(false));
  const Rigid3d world_from_rig = Turn(-0.4, {0, 1, 0}, {100, 1600, -300});
  const Rigid3d ahat_from_tool = Turn(2.1, {0.3, -1, 0.2}, {20, -10, 450});
  const NavigationState s = nav.Place(1.0, Tracked(1.0, ahat_from_tool), world_from_rig, 4);
  ASSERT_EQ(s.status, NavigationStatus::kTracking);
  ASSERT_TRUE(s.world_from_image);
  // Eq. (8) written out with 4 x 4 matrices, independently of Rigid3d composition.
  const Eigen::Matrix4d expected = world_from_rig.ToMatrix() * Camera().rig_from_ahat().ToMatrix() *
                                   ahat_from_tool.ToMatrix() *
                                   Case(false).tool_from_image.ToMatrix();
  EXPECT_THAT(*s.world_from_image, RigidNear(Rigid3d::FromMatrix(expected), kExactRad, 1e-9));
  ASSERT_EQ(s.plan.size(), 2u);
  const NavigationCase c = Case(false);
  const Trajectory& p = c.plan[1];
  const Eigen::Vector4d entry = expected * p.entry_lps_mm.homogeneous();
  EXPECT_NEAR((s.plan[1].entry_in_world - entry.head<3>()).norm(), 0.0, 1e-9);
  const Eigen::Vector3d target_in_tool = Case(false).tool_from_image * p.target_lps_mm;
  EXPECT_NEAR((s.plan[1].target_in_tool - target_in_tool).norm(), 0.0, kExactMm);
  EXPECT_EQ(s.reference_age_s, 0.0);
}

TEST(Navigator, HoldsThenReportsStaleAfter100Ms) {
  Navigator nav(Camera(), Case(false));
  const Rigid3d world_from_rig = Turn(0.1, {0, 1, 0}, {0, 1600, 0});
  const Rigid3d ahat_from_tool = Turn(3.0, {1, 0, 0}, {0, 0, 400});
  EXPECT_EQ(nav.Place(0.0, Tracked(0.0, std::nullopt), world_from_rig, 0).status,
            NavigationStatus::kReferenceLost);  // never seen
  const NavigationState seen = nav.Place(1.0, Tracked(1.0, ahat_from_tool), world_from_rig, 4);
  const NavigationState held = nav.Place(1.09, Tracked(1.09, std::nullopt), world_from_rig, 0);
  EXPECT_EQ(held.status, NavigationStatus::kHolding);
  ASSERT_TRUE(held.world_from_image);
  EXPECT_THAT(*held.world_from_image, RigidNear(*seen.world_from_image, 0.0, 0.0));
  EXPECT_NEAR(held.reference_age_s, 0.09, 1e-12);
  const NavigationState stale = nav.Place(1.11, Tracked(1.11, std::nullopt), world_from_rig, 0);
  EXPECT_EQ(stale.status, NavigationStatus::kReferenceLost);
  EXPECT_FALSE(stale.world_from_image);
  EXPECT_TRUE(stale.plan.empty());
  // Once stale, a later frame inside the window of the old sighting does not revive it.
  EXPECT_FALSE(nav.Place(1.12, Tracked(1.12, std::nullopt), world_from_rig, 0).world_from_image);
  EXPECT_EQ(nav.Place(1.13, Tracked(1.13, ahat_from_tool), world_from_rig, 4).status,
            NavigationStatus::kTracking);
}

TEST(Navigator, AJumpedReferencePoseIsLeftOutAndTheHeldPoseIsTheRecentMean) {
  Navigator nav(Camera(), Case(false));
  const Rigid3d world_from_rig = Turn(0.1, {0, 1, 0}, {0, 1600, 0});
  const Rigid3d ahat_from_tool = Turn(3.0, {1, 0, 0}, {0, 0, 400});
  // 20 frames at 45 Hz whose poses alternate 0.2 mm either side of ahat_from_tool (noise).
  NavigationState last;
  for (int i = 0; i < 20; ++i) {
    Rigid3d pose = ahat_from_tool;
    pose.translation.x() += i % 2 == 0 ? 0.2 : -0.2;
    last = nav.Place(i / 45.0, Tracked(i / 45.0, pose), world_from_rig, 4);
    EXPECT_EQ(last.status, NavigationStatus::kTracking) << i;
    EXPECT_FALSE(last.reference_pose_jump) << i;
  }
  // A 5 deg tilt (a wrong correspondence): measured, left out, held.
  const Rigid3d tilted = ahat_from_tool * Turn(5.0 * std::numbers::pi / 180.0, {0, 1, 0}, {});
  const NavigationState jumped =
      nav.Place(20 / 45.0, Tracked(20 / 45.0, tilted), world_from_rig, 4);
  EXPECT_EQ(jumped.status, NavigationStatus::kHolding);
  EXPECT_TRUE(jumped.reference_pose_jump);
  EXPECT_EQ(jumped.reference_pose_check.status, PoseConsistency::kJump);
  EXPECT_NEAR(jumped.reference_pose_check.rotation_rad, 5.0 * std::numbers::pi / 180.0, 1e-3);
  EXPECT_FALSE(jumped.ahat_from_tool);
  EXPECT_EQ(nav.reference_pose_jumps(), 1);
  // Held: the mean of the last 0.1 s (5 poses, +-0.2 mm alternating: 0.04 mm from the centre),
  // not the last pose (0.2 mm off).
  const Rigid3d centre = world_from_rig * Camera().rig_from_ahat() * ahat_from_tool *
                         nav.navigation_case().tool_from_image;
  ASSERT_TRUE(jumped.world_from_image);
  EXPECT_NEAR(TranslationDistanceMm(*jumped.world_from_image, centre), 0.04, 1e-6);
  EXPECT_NEAR(TranslationDistanceMm(*last.world_from_image, centre), 0.2, 1e-6);
  // The next good pose tracks again.
  EXPECT_EQ(nav.Place(21 / 45.0, Tracked(21 / 45.0, ahat_from_tool), world_from_rig, 4).status,
            NavigationStatus::kTracking);
}

// A reference whose orientation the filter has not yet averaged (a plate's first frames, its
// filtered_rotation_sd_rad one frame's fit) places the plan and says SETTLING; the held picture
// keeps the state of the pose it came from; an averaged one is settled; no sd, no claim either way.
TEST(Navigator, AReferenceIsSettlingUntilItsOrientationIsAveraged) {
  Navigator nav(Camera(), Case(false));
  const Rigid3d world_from_rig = Turn(0.1, {0, 1, 0}, {0, 1600, 0});
  const Rigid3d ahat_from_tool = Turn(3.0, {1, 0, 0}, {0, 0, 600});
  const auto frame = [&](double t_s, std::optional<double> sd_deg) {
    TrackingFrame f = Tracked(t_s, ahat_from_tool);
    if (sd_deg) f.tools.front().filtered_rotation_sd_rad = *sd_deg * kDegToRad;
    return f;
  };
  const NavigationState first = nav.Place(0.0, frame(0.0, 0.52), world_from_rig, 4);
  EXPECT_EQ(first.status, NavigationStatus::kTracking);
  ASSERT_TRUE(first.world_from_image && first.reference_rotation_sd_rad);
  EXPECT_TRUE(first.reference_settling);
  EXPECT_NEAR(*first.reference_rotation_sd_rad, 0.52 * kDegToRad, 1e-15);
  const NavigationState held = nav.Place(0.05, Tracked(0.05, std::nullopt), world_from_rig, 0);
  EXPECT_EQ(held.status, NavigationStatus::kHolding);
  EXPECT_TRUE(held.reference_settling);
  EXPECT_FALSE(nav.Place(0.2, frame(0.2, 0.34), world_from_rig, 4).reference_settling);
  EXPECT_FALSE(nav.Place(0.3, frame(0.3, std::nullopt), world_from_rig, 4).reference_settling);
  const NavigationState lost = nav.Place(1.0, Tracked(1.0, std::nullopt), world_from_rig, 0);
  EXPECT_FALSE(lost.reference_settling || lost.reference_rotation_sd_rad);  // nothing placed
  NavigatorOptions never;
  never.settled_rotation_sd_rad = std::numeric_limits<double>::infinity();
  Navigator off(Camera(), Case(false), never);
  EXPECT_FALSE(off.Place(0.0, frame(0.0, 5.0), world_from_rig, 4).reference_settling);
  never.settled_rotation_sd_rad = 0.0;
  EXPECT_THROW(Navigator(Camera(), Case(false), never), PreconditionError);
}

TEST(Navigator, NoWorldPoseWithoutRigPose) {
  Navigator nav(Camera(), Case(false));
  const NavigationState s =
      nav.Place(0.5, Tracked(0.5, Turn(0.2, {0, 0, 1}, {0, 0, 400})), std::nullopt, 4);
  EXPECT_EQ(s.status, NavigationStatus::kNoWorldPose);
  EXPECT_TRUE(s.ahat_from_tool);
  EXPECT_FALSE(s.world_from_image);
}

TEST(Navigator, InstrumentOnThePlannedLineGivesDepthAndZeroAngle) {
  NavigationCase c = Case(true);
  Navigator nav(Camera(), c);
  nav.SelectTrajectory(1);
  const Rigid3d world_from_rig = Turn(0.3, {0, 1, 0}, {50, 1500, 20});
  const Rigid3d ahat_from_tool = Turn(2.5, {1, 0.2, 0}, {-20, 30, 420});
  const Rigid3d world_from_ahat = world_from_rig * Camera().rig_from_ahat();
  const Rigid3d world_from_image = world_from_ahat * ahat_from_tool * c.tool_from_image;
  // Put the drill tip 12 mm before the entry of trajectory 1, its axis along the plan.
  const Trajectory& p = c.plan[1];
  const Eigen::Vector3d entry = world_from_image * p.entry_lps_mm;
  const Eigen::Vector3d target = world_from_image * p.target_lps_mm;
  const Eigen::Vector3d u = (target - entry).normalized();
  const Eigen::Vector3d tip = entry - 12.0 * u;
  // Drill axis (centroid -> tip) in its frame, rotated onto u; then placed at the tip.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& m : c.instrument->markers_in_tool) centroid += m / 4.0;
  const Eigen::Vector3d axis_in_tool = (*c.instrument->tip_in_tool - centroid).normalized();
  const Eigen::Quaterniond r = Eigen::Quaterniond::FromTwoVectors(axis_in_tool, u);
  const Rigid3d world_from_drill(r, tip - r * *c.instrument->tip_in_tool);
  const Rigid3d ahat_from_drill = world_from_ahat.Inverse() * world_from_drill;
  const NavigationState s =
      nav.Place(2.0, Tracked(2.0, ahat_from_tool, ahat_from_drill), world_from_rig, 8);
  ASSERT_TRUE(s.guidance);
  constexpr double kTolMm = 1e-9, kTolRad = 1e-7;  // double round trips
  EXPECT_NEAR(s.guidance->tip_to_entry_mm, 12.0, kTolMm);
  EXPECT_NEAR(s.guidance->angle_to_axis_rad, 0.0, kTolRad);
  EXPECT_NEAR(s.guidance->remaining_depth_mm, 12.0 + (target - entry).norm(), kTolMm);
  EXPECT_NEAR(s.guidance->lateral_offset_mm, 0.0, 1e-6);
  ASSERT_TRUE(s.tool_from_instrument);
  EXPECT_THAT(*s.tool_from_instrument,
              RigidNear(ahat_from_tool.Inverse() * ahat_from_drill, kExactRad, 1e-9));
}

TEST(Guidance, AnalyticOffsetAndAngle) {
  // Plan along +z from the origin to 80 mm; tip 3 mm to the side at depth 30, axis tilted 30 deg.
  const double tilt = std::numbers::pi / 6.0;
  const Guidance g =
      ComputeGuidance({3, 0, 30}, {std::sin(tilt), 0, std::cos(tilt)}, {0, 0, 0}, {0, 0, 80});
  EXPECT_NEAR(g.tip_to_entry_mm, std::hypot(3.0, 30.0), 1e-12);
  EXPECT_NEAR(g.angle_to_axis_rad, tilt, 1e-12);
  EXPECT_NEAR(g.remaining_depth_mm, 50.0, 1e-12);
  EXPECT_NEAR(g.lateral_offset_mm, 3.0, 1e-12);
  EXPECT_NEAR(AngleBetweenRad({1, 0, 0}, {-1, 1e-9, 0}), std::numbers::pi, 1e-8);
  EXPECT_THROW(ComputeGuidance({0, 0, 0}, {0, 0, 1}, {1, 1, 1}, {1, 1, 1}), PreconditionError);
}

TEST(Navigator, RejectsBadCase) {
  NavigationCase c = Case(true);
  c.instrument->tip_in_tool.reset();
  EXPECT_THROW(Navigator(Camera(), c), PreconditionError);
  c = Case(false);
  c.plan[0].target_lps_mm = c.plan[0].entry_lps_mm;
  EXPECT_THROW(Navigator(Camera(), c), PreconditionError);
  Navigator nav(Camera(), Case(false));
  EXPECT_THROW(nav.SelectTrajectory(2), PreconditionError);
}

}  // namespace
}  // namespace tofnav
