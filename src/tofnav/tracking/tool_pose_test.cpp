// SPDX-License-Identifier: BSD-3-Clause
// Matching, occlusion, arbitration and ambiguity on synthetic detections.
#include "tofnav/tracking/tool_pose.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "marker_test_scenes.hpp"
#include "matchers.hpp"
#include "tracking_test_tools.hpp"

namespace tofnav {
namespace {

using testing::ReferenceTool;
using testing::SecondTool;
using testing::ToolDetections;

constexpr double kNoiseMm = 0.15;                               // marker centre noise
constexpr double kPoseRotTolRad = 0.01, kPoseTransTolMm = 0.5;  // ~4 sigma for 4 markers

TEST(EstimateToolPoses, FindsAToolAmongShuffledAndSpuriousDetections) {
  std::mt19937_64 rng(2);
  const ToolGeometry tools[] = {ReferenceTool()};
  const Rigid3d truth = testing::RandomFacingPose(rng, 450.0);
  std::vector<DetectedMarker> d = ToolDetections(tools[0], truth, kNoiseMm, rng);
  testing::AddSpurious(d, 12, rng);
  std::vector<int> order(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) order[i] = static_cast<int>(i);
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<DetectedMarker> shuffled;
  for (const int i : order) shuffled.push_back(d[static_cast<std::size_t>(i)]);
  const ToolPoseResult r = EstimateToolPoses(shuffled, tools)[0];
  ASSERT_EQ(r.status, ToolStatus::kOk);
  EXPECT_THAT(*r.ahat_from_tool, RigidNear(truth, kPoseRotTolRad, kPoseTransTolMm));
  for (int k = 0; k < 4; ++k) EXPECT_EQ(order[static_cast<std::size_t>(r.marker_detection[k])], k);
  EXPECT_EQ(r.visible_markers, 4);
  EXPECT_LT(r.fre_rms_mm, 4.0 * kNoiseMm);
}

TEST(EstimateToolPoses, HandlesOcclusionAndReportsTooFewOrOutOfView) {
  std::mt19937_64 rng(3);
  const ToolGeometry tools[] = {ReferenceTool()};
  const Rigid3d truth = testing::RandomFacingPose(rng, 600.0);
  std::vector<DetectedMarker> d = ToolDetections(tools[0], truth, kNoiseMm, rng);
  d.erase(d.begin() + 1);  // one marker occluded
  ToolPoseResult r = EstimateToolPoses(d, tools)[0];
  ASSERT_EQ(r.status, ToolStatus::kPartiallyOccluded);
  EXPECT_EQ(r.marker_detection[1], -1);
  EXPECT_THAT(*r.ahat_from_tool, RigidNear(truth, 3.0 * kPoseRotTolRad, kPoseTransTolMm));
  d.erase(d.begin());  // two left
  r = EstimateToolPoses(d, tools)[0];
  EXPECT_EQ(r.status, ToolStatus::kTooFewMarkers);
  EXPECT_FALSE(r.ahat_from_tool.has_value());
  EXPECT_EQ(EstimateToolPoses({}, tools)[0].status, ToolStatus::kTooFewMarkers);
  std::vector<DetectedMarker> unrelated;
  testing::AddSpurious(unrelated, 5, rng, {0, 0, 450}, 400.0);
  EXPECT_EQ(EstimateToolPoses(unrelated, tools)[0].status, ToolStatus::kOutOfView);
}

TEST(EstimateToolPoses, NeverSwapsTwoToolsAmidSpuriousBlobs) {
  std::mt19937_64 rng(4);
  const ToolGeometry tools[] = {ReferenceTool(), SecondTool()};
  int found = 0;
  constexpr int kTrials = 40;
  for (int trial = 0; trial < kTrials; ++trial) {
    const Rigid3d a = testing::RandomFacingPose(rng, 400.0 + 5.0 * trial);
    Rigid3d b = testing::RandomFacingPose(rng, 450.0 + 5.0 * trial);
    b.translation.x() += 160.0;
    std::vector<DetectedMarker> d = ToolDetections(tools[0], a, kNoiseMm, rng);
    const std::vector<DetectedMarker> db = ToolDetections(tools[1], b, kNoiseMm, rng);
    d.insert(d.end(), db.begin(), db.end());
    testing::AddSpurious(d, 20, rng);
    const std::vector<ToolPoseResult> r = EstimateToolPoses(d, tools);
    for (int t = 0; t < 2; ++t) {
      if (!r[static_cast<std::size_t>(t)].ahat_from_tool) continue;  // allowed: no pose
      ++found;
      EXPECT_THAT(*r[static_cast<std::size_t>(t)].ahat_from_tool,
                  RigidNear(t == 0 ? a : b, 3.0 * kPoseRotTolRad, kPoseTransTolMm))
          << "trial " << trial << " tool " << t;
    }
  }
  EXPECT_GE(found, 2 * kTrials * 9 / 10);  // and nearly always a pose
}

TEST(EstimateToolPoses, FlagsSymmetryAndTwinToolsAsAmbiguousUnlessThePriorDecides) {
  ToolGeometry rectangle;
  rectangle.name = "rectangle";
  rectangle.markers_in_tool = {{0, 0, 0}, {80, 0, 0}, {80, 50, 0}, {0, 50, 0}};
  std::mt19937_64 rng(5);
  const Rigid3d truth = testing::FacingToolPose({0, 0, 500}, 0.3, 0.2);
  const std::vector<DetectedMarker> d = ToolDetections(rectangle, truth, 0.05, rng);
  const ToolGeometry tools[] = {rectangle};
  EXPECT_EQ(EstimateToolPoses(d, tools)[0].status, ToolStatus::kAmbiguous);
  const std::optional<Rigid3d> prior[] = {truth};
  const ToolPoseResult with_prior = EstimateToolPoses(d, tools, prior)[0];
  ASSERT_EQ(with_prior.status, ToolStatus::kOk);
  EXPECT_THAT(*with_prior.ahat_from_tool, RigidNear(truth, kPoseRotTolRad, kPoseTransTolMm));
  // Two identical tools in view: which is which cannot be told.
  const ToolGeometry twins[] = {ReferenceTool(), ReferenceTool()};
  std::vector<DetectedMarker> both =
      ToolDetections(twins[0], testing::FacingToolPose({-80, 0, 450}), 0.05, rng);
  const std::vector<DetectedMarker> other =
      ToolDetections(twins[1], testing::FacingToolPose({90, 0, 450}), 0.05, rng);
  both.insert(both.end(), other.begin(), other.end());
  for (const ToolPoseResult& r : EstimateToolPoses(both, twins)) {
    EXPECT_EQ(r.status, ToolStatus::kAmbiguous);
  }
}

// A wrong triangle of a four-marker tool leaves its fourth marker where the images show empty
// space before a far wall; the right one leaves it under the hand that hides it.
TEST(EstimateToolPoses, APoseThatPutsAnUnmatchedMarkerInEmptySpaceIsRefused) {
  // C and D lie at the same distances from A and B (D is C turned by 60 deg about AB), so the
  // triangle ABD fits the blobs of A, B, C exactly: geometry alone cannot tell the two poses.
  ToolGeometry tool;
  tool.name = "near_twin_triangles";
  tool.markers_in_tool = {{0, 0, 0}, {60, 0, 0}, {20, 40, 0}, {20, 20, 34.641}};
  std::mt19937_64 rng(11);
  const Rigid3d truth = testing::FacingToolPose({-10, 5, 500}, 0.9, 0.3);
  const Rigid3d wrong =  // tool marker D onto blob C: turned by -60 deg about AB (tool x)
      truth * Rigid3d(Eigen::Quaterniond(
                          Eigen::AngleAxisd(-std::numbers::pi / 3.0, Eigen::Vector3d::UnitX())),
                      Eigen::Vector3d::Zero());
  std::vector<DetectedMarker> d = ToolDetections(tool, truth, 0.05, rng);
  d.pop_back();  // D is hidden by a hand 80 mm in front of it
  const ToolGeometry tools[] = {tool};
  EXPECT_EQ(EstimateToolPoses(d, tools)[0].status, ToolStatus::kAmbiguous);
  // A prior at the wrong pose (a stale one, or a wrong triangle that fits better) picks it.
  const std::optional<Rigid3d> prior[] = {wrong};
  const ToolPoseResult guessed = EstimateToolPoses(d, tools, prior)[0];
  ASSERT_TRUE(guessed.ahat_from_tool.has_value());
  EXPECT_THAT(*guessed.ahat_from_tool, RigidNear(wrong, 3.0 * kPoseRotTolRad, kPoseTransTolMm));

  AhatFrame frame;  // a far dark wall, and the hand over D
  frame.range_mm = Image<std::uint16_t>(kAhatWidth, kAhatHeight, 900);
  frame.ab = Image<std::uint16_t>(kAhatWidth, kAhatHeight, 60);
  const Eigen::Vector3d hidden = truth * tool.markers_in_tool[3];
  const Eigen::Vector2d hand_px = *testing::TestCamera().Project(hidden);
  for (int v = 0; v < kAhatHeight; ++v) {
    for (int u = 0; u < kAhatWidth; ++u) {
      if ((Eigen::Vector2d(u, v) - hand_px).norm() < 8.0) {
        frame.range_mm(u, v) = static_cast<std::uint16_t>(hidden.norm() - 80.0);
      }
    }
  }
  // With the images the wrong pose is refused; the right one, which it still rivals, is not
  // accepted in its place: the test only ever takes a pose away.
  const MarkerVoidTest void_test(frame, testing::TestCamera());
  const ToolPoseResult r = EstimateToolPoses(d, tools, prior, {}, {}, &void_test)[0];
  EXPECT_FALSE(r.ahat_from_tool.has_value());
  EXPECT_EQ(r.status, ToolStatus::kAmbiguous);
  EXPECT_EQ(r.candidates_refused_void, 1);
  ToolPoseOptions keep;
  keep.refuse_void_poses = false;
  EXPECT_TRUE(EstimateToolPoses(d, tools, prior, keep, {}, &void_test)[0].ahat_from_tool);

  // Without the hand the right pose's D is empty space too: both are refused.
  frame.range_mm = Image<std::uint16_t>(kAhatWidth, kAhatHeight, 900);
  const MarkerVoidTest no_hand(frame, testing::TestCamera());
  const ToolPoseResult none = EstimateToolPoses(d, tools, prior, {}, {}, &no_hand)[0];
  EXPECT_FALSE(none.ahat_from_tool.has_value());
  EXPECT_EQ(none.candidates_refused_void, 2);
}

TEST(EstimateToolPoses, AToolSeenWholeIsNotAmbiguousWithAnotherToolsTriangleOfIt) {
  // The second tool's markers are three of the first's (its fourth elsewhere): seeing all four of
  // the first, the second's 3-marker fit on those blobs explains less and needs an occlusion.
  const ToolGeometry whole = ReferenceTool();
  ToolGeometry triangle = whole;
  triangle.name = "triangle";
  triangle.markers_in_tool[3] = {0.0, 0.0, 40.0};  // off the plane: never among the four blobs
  std::mt19937_64 rng(8);
  const Rigid3d truth = testing::FacingToolPose({0, 0, 700}, 0.2, -0.1);
  // At 700 mm a blob's centre can be 1.5 mm off: the whole tool's FRE (about 0.6 mm) then
  // exceeds the triangle's on the three good blobs plus its occlusion penalty (0.5 mm).
  const Eigen::Vector3d shifted = truth * whole.markers_in_tool[3] + Eigen::Vector3d(1.5, 0, 0);
  std::vector<DetectedMarker> d = ToolDetections(whole, truth, 0.02, rng);
  d[3] = testing::DetectionAt(shifted, whole.SurfaceToCentreMm());
  const ToolGeometry tools[] = {whole, triangle};
  const std::vector<ToolPoseResult> r = EstimateToolPoses(d, tools);
  ASSERT_EQ(r[0].status, ToolStatus::kOk);
  EXPECT_THAT(*r[0].ahat_from_tool, RigidNear(truth, 2.0 * kPoseRotTolRad, kPoseTransTolMm));
  EXPECT_NE(r[1].status, ToolStatus::kOk);
  EXPECT_NE(r[1].status, ToolStatus::kPartiallyOccluded);
  // With only the shared three blobs in view, either tool could be there: reported, not guessed.
  d.pop_back();
  for (const ToolPoseResult& t : EstimateToolPoses(d, tools)) {
    EXPECT_EQ(t.status, ToolStatus::kAmbiguous);
  }
}

TEST(EstimateToolPoses, AHeadframeWithOnePlateInViewIsNotLostToAnotherToolsTriangleOfThatPlate) {
  // A headframe of two plates (8 markers, the second 230 mm away and out of view) and an
  // instrument whose triangle fits three of the seen plate's markers. The headframe's four
  // blobs carry four penalties of occlusion, the triangle one: scored alone, the triangle won and
  // the instrument was shown on the plate (a wrong identity). The four blobs explain more.
  const ToolGeometry plate = ReferenceTool();
  ToolGeometry headframe = plate;
  headframe.name = "headframe";
  for (const Eigen::Vector3d& m : SecondTool().markers_in_tool) {  // another layout: no twin
    headframe.markers_in_tool.push_back(m + Eigen::Vector3d(230.0, 0.0, -40.0));
  }
  ToolGeometry instrument = plate;
  instrument.name = "instrument";
  instrument.markers_in_tool[3] = {0.0, 0.0, 40.0};  // off the plane: never among the four blobs
  std::mt19937_64 rng(11);
  const Rigid3d truth = testing::FacingToolPose({0, 0, 600}, 0.1, -0.2);
  std::vector<DetectedMarker> d = ToolDetections(plate, truth, 0.1, rng);
  const ToolGeometry tools[] = {headframe, instrument};
  const std::vector<ToolPoseResult> r = EstimateToolPoses(d, tools);
  ASSERT_EQ(r[0].status, ToolStatus::kPartiallyOccluded);
  EXPECT_EQ(r[0].visible_markers, 4);
  EXPECT_THAT(*r[0].ahat_from_tool, RigidNear(truth, kPoseRotTolRad, kPoseTransTolMm));
  EXPECT_FALSE(r[1].ahat_from_tool.has_value());
}

TEST(EstimateToolPoses, RejectsTheMirrorTwinAndBadInput) {
  ToolGeometry mirror = ReferenceTool();
  mirror.name = "mirror";
  mirror.min_visible = 4;
  for (Eigen::Vector3d& p : mirror.markers_in_tool) p.x() = -p.x();
  std::mt19937_64 rng(6);
  const std::vector<DetectedMarker> d =
      ToolDetections(ReferenceTool(), testing::RandomFacingPose(rng, 500.0), kNoiseMm, rng);
  const ToolGeometry tools[] = {mirror, ReferenceTool()};
  const std::vector<ToolPoseResult> r = EstimateToolPoses(d, tools);
  EXPECT_EQ(r[0].status, ToolStatus::kTooFewMarkers);  // the real tool took every detection
  EXPECT_EQ(r[1].status, ToolStatus::kOk);
  EXPECT_EQ(EstimateToolPoses(d, std::span(tools, 1))[0].status, ToolStatus::kOutOfView);
  ToolGeometry bad = ReferenceTool();
  bad.markers_in_tool.resize(2);
  const ToolGeometry bad_tools[] = {bad};
  EXPECT_THROW(EstimateToolPoses(d, bad_tools), std::invalid_argument);
  const std::optional<Rigid3d> priors[] = {std::nullopt, std::nullopt, std::nullopt};
  EXPECT_THROW(EstimateToolPoses(d, tools, priors), std::invalid_argument);
  ToolPoseOptions tiny_budget;
  tiny_budget.max_search_nodes = 3;  // an exhausted search never guesses
  EXPECT_EQ(EstimateToolPoses(d, std::span(tools + 1, 1), {}, tiny_budget)[0].status,
            ToolStatus::kAmbiguous);
}

TEST(EstimateToolPose, WorksOnCentresDirectly) {
  std::mt19937_64 rng(7);
  const Rigid3d truth = testing::RandomFacingPose(rng, 350.0);
  Points3d centres;
  for (const Eigen::Vector3d& m : ReferenceTool().markers_in_tool) centres.push_back(truth * m);
  const ToolPoseResult r = EstimateToolPose(centres, ReferenceTool());
  ASSERT_EQ(r.status, ToolStatus::kOk);
  EXPECT_THAT(*r.ahat_from_tool, RigidNear(truth, 1e-9, 1e-9));
  EXPECT_STREQ(ToString(r.status), "ok");
}

}  // namespace
}  // namespace tofnav
