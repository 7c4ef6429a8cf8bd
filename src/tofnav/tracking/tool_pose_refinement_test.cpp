// SPDX-License-Identifier: BSD-3-Clause
// EstimateToolPoses's refinement on synthetic detections: rays weigh over ranges, and disc ranges
// long by their entrance angle are corrected from the pose (docs/tracking.md 6).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "matchers.hpp"
#include "tofnav/tracking/tool_pose.hpp"
#include "tracking_test_tools.hpp"

namespace tofnav {
namespace {

// A small flat tool of four 10 mm discs (tape on a plate), spread 60-80 mm.
ToolGeometry FlatDiscTool(const char* name) {
  ToolGeometry tool;
  tool.name = name;
  tool.marker_type = MarkerType::kDisc;
  tool.marker_diameter_mm = 10.0;
  tool.markers_in_tool = {{-35, -5, 0}, {30, 0, 0}, {5, -30, 0}, {-5, 42, 0}};
  return tool;
}

TEST(EstimateToolPoses, RefinementWeighsRaysOverRangesAndKeepsFreMeaningful) {
  // A small flat tool tilted 0.5 rad at 500 mm whose marker ranges alone carry +-1 mm errors.
  constexpr double kPixelPitchRad = 1.0 / 254.0;  // AHAT focal length
  constexpr double kFreTolMm = 1e-9;              // FRE is the RMS of the residuals
  const ToolGeometry tool = FlatDiscTool("flat");
  const ToolGeometry tools[] = {tool};
  const Rigid3d truth = testing::FacingToolPose({20.0, -10.0, 500.0}, 0.5, 0.3);
  const double range_error_mm[] = {1.0, -1.0, -1.0, 1.0};
  std::vector<DetectedMarker> d;
  for (std::size_t i = 0; i < tool.markers_in_tool.size(); ++i) {
    const Eigen::Vector3d c = truth * tool.markers_in_tool[i];
    d.push_back(testing::DetectionAt(c.normalized() * (c.norm() + range_error_mm[i]), 0.0));
    d.back().pixel_pitch_rad = kPixelPitchRad;
  }
  ToolPoseOptions kabsch_options;
  kabsch_options.refinement.enabled = false;
  const ToolPoseResult kabsch = EstimateToolPoses(d, tools, {}, kabsch_options)[0];
  ToolPoseOptions options;  // rays far more precise than the 1 mm ranges (here: exact)
  options.refinement.lateral_sigma_px = 0.02;
  const ToolPoseResult refined = EstimateToolPoses(d, tools, {}, options)[0];
  ASSERT_EQ(kabsch.status, ToolStatus::kOk);
  ASSERT_EQ(refined.status, ToolStatus::kOk);
  const double kabsch_error = RotationDistanceRad(*kabsch.ahat_from_tool, truth);
  const double refined_error = RotationDistanceRad(*refined.ahat_from_tool, truth);
  EXPECT_LT(refined_error, 0.7 * kabsch_error);
  double sum2 = 0.0;
  for (const double e : refined.residuals_mm) sum2 += e * e;
  ASSERT_EQ(refined.residuals_mm.size(), 4u);
  EXPECT_NEAR(refined.fre_rms_mm, std::sqrt(sum2 / 4.0), kFreTolMm);
  EXPECT_GE(refined.fre_rms_mm, kabsch.fre_rms_mm);  // Kabsch minimises the isotropic FRE
  ToolPoseOptions bad;
  bad.refinement.lateral_sigma_px = 0.0;
  EXPECT_THROW(EstimateToolPoses(d, tools, {}, bad), std::invalid_argument);
}

TEST(EstimateToolPoses, DiscRangesLongByTheirEntranceAngleAreCorrectedFromThePose) {
  // A flat tape tool tilted 0.7 rad at 450 mm: each disc reads farther by 2.1 mm per radian of
  // its entrance angle (the simulator's tape, docs/simulator.md 10). Without the term the pose
  // sits about 1.5 mm too far; with it, within the refinement's rounding of exact data.
  constexpr double kGainMmPerRad = 2.1;
  constexpr double kPixelPitchRad = 1.0 / 254.0;
  constexpr double kCorrectedTolMm = 0.05;  // one refit: beta is off by the first pose's tilt
  const ToolGeometry tool = FlatDiscTool("tape");
  const ToolGeometry tools[] = {tool};
  const Rigid3d truth = testing::FacingToolPose({20.0, -10.0, 450.0}, 0.7, 0.3);
  const Eigen::Vector3d normal = truth.rotation * Eigen::Vector3d::UnitZ();
  std::vector<DetectedMarker> d;
  for (const Eigen::Vector3d& m : tool.markers_in_tool) {
    const Eigen::Vector3d c = truth * m;
    const double beta = std::acos(std::abs(normal.dot(c.normalized())));
    d.push_back(testing::DetectionAt(c.normalized() * (c.norm() + kGainMmPerRad * beta), 0.0));
    d.back().pixel_pitch_rad = kPixelPitchRad;
  }
  const ToolPoseResult plain = EstimateToolPoses(d, tools, {}, ToolPoseOptions{})[0];
  ToolPoseOptions options;
  options.marker_entrance_gain_mm_per_rad = kGainMmPerRad;
  const ToolPoseResult corrected = EstimateToolPoses(d, tools, {}, options)[0];
  ASSERT_EQ(plain.status, ToolStatus::kOk);
  ASSERT_EQ(corrected.status, ToolStatus::kOk);
  EXPECT_GT(TranslationDistanceMm(*plain.ahat_from_tool, truth), 1.0);
  EXPECT_LT(TranslationDistanceMm(*corrected.ahat_from_tool, truth), kCorrectedTolMm);
  // A sphere tool's hand-made detections carry no core pixels to place the term on: unchanged.
  ToolGeometry spheres = tool;
  spheres.marker_type = MarkerType::kSphere;
  const ToolGeometry sphere_tools[] = {spheres};
  EXPECT_LT(TranslationDistanceMm(
                *EstimateToolPoses(d, sphere_tools, {}, options)[0].ahat_from_tool,
                *EstimateToolPoses(d, sphere_tools, {}, ToolPoseOptions{})[0].ahat_from_tool),
            1e-12);
}

}  // namespace
}  // namespace tofnav
