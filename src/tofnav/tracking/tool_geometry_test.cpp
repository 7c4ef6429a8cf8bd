// SPDX-License-Identifier: BSD-3-Clause
// Tool validation and the symmetry / confusion report.
#include "tofnav/tracking/tool_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tracking_test_tools.hpp"

namespace tofnav {
namespace {

using testing::ReferenceTool;
using testing::SecondTool;

TEST(ToolGeometry, CheckRejectsUnusableTools) {
  ToolGeometry tool = ReferenceTool();
  EXPECT_NO_THROW(tool.Check());
  tool.markers_in_tool.resize(2);
  EXPECT_THROW(tool.Check(), std::invalid_argument);
  tool = ReferenceTool();
  tool.markers_in_tool[2] = tool.markers_in_tool[0] + Eigen::Vector3d(3.0, 0.0, 0.0);  // overlap
  EXPECT_THROW(tool.Check(), std::invalid_argument);
  tool = ReferenceTool();
  tool.markers_in_tool = {{0, 0, 0}, {40, 0, 0}, {90, 0, 0.2}};  // collinear
  EXPECT_THROW(tool.Check(), std::invalid_argument);
  tool = ReferenceTool();
  tool.min_visible = 5;
  EXPECT_THROW(tool.Check(), std::invalid_argument);
  tool = ReferenceTool();
  tool.markers_in_tool[1].x() = NAN;
  EXPECT_THROW(tool.Check(), std::invalid_argument);
  EXPECT_DOUBLE_EQ(ReferenceTool().SurfaceToCentreMm(), 5.75);
  tool = ReferenceTool();
  tool.marker_type = MarkerType::kDisc;
  EXPECT_DOUBLE_EQ(tool.SurfaceToCentreMm(), 0.0);
}

TEST(AnalyzeToolGeometry, ReportsDistancesAndDistinctness) {
  const ToolGeometry others[] = {SecondTool(), ReferenceTool()};
  const ToolGeometryReport r = AnalyzeToolGeometry(ReferenceTool(), others);
  ASSERT_EQ(r.distances_mm.size(), 6u);
  EXPECT_NEAR(r.distances_mm[0],
              (ReferenceTool().markers_in_tool[0] - ReferenceTool().markers_in_tool[1]).norm(),
              1e-12);
  EXPECT_GE(r.min_distance_difference_mm, 7.0);  // designed: within-tool edges differ by >= 7 mm
  EXPECT_GT(r.self_symmetry_fre_mm, 3.0);        // no symmetry
  EXPECT_GT(r.planarity_rms_mm, 3.0);
  ASSERT_EQ(r.min_segment_difference_mm.size(), 2u);
  EXPECT_NEAR(r.min_segment_difference_mm[0], 5.134, 1e-3);  // designed: between tools >= 5 mm
  EXPECT_GT(r.confusion_fre_mm[0], 1.0);
  EXPECT_NEAR(r.min_segment_difference_mm[1], 0.0, 1e-12);  // against itself: identical
  EXPECT_NEAR(r.confusion_fre_mm[1], 0.0, 1e-9);
}

TEST(AnalyzeToolGeometry, FindsSymmetryAndTellsMirrorTwinsApart) {
  ToolGeometry rectangle;
  rectangle.name = "rectangle";
  rectangle.markers_in_tool = {{0, 0, 0}, {80, 0, 0}, {80, 50, 0}, {0, 50, 0}};
  EXPECT_LT(AnalyzeToolGeometry(rectangle).self_symmetry_fre_mm, 1e-9);
  ToolGeometry tool = ReferenceTool();
  tool.min_visible = 4;  // 3-marker triangles of mirror twins are always congruent
  ToolGeometry mirror = tool;
  for (Eigen::Vector3d& p : mirror.markers_in_tool) p.x() = -p.x();
  const ToolGeometry others[] = {mirror};
  const ToolGeometryReport r = AnalyzeToolGeometry(tool, others);
  EXPECT_NEAR(r.min_segment_difference_mm[0], 0.0, 1e-12);  // same distances...
  EXPECT_GT(r.confusion_fre_mm[0], 3.0);                    // ...but no proper rigid fit
}

// Two flat plates of four discs each, 200 mm apart and turned 40 deg against each other, tracked
// as one tool (a headframe's two reference plates): each disc gets its own plate's normal, where
// the whole tool's plane would be off by about 20 deg for both.
TEST(MarkerPlaneNormals, EachDiscGetsItsOwnPlatesNormal) {
  constexpr double kTolRad = 1e-9;  // exact geometry: only rounding
  ToolGeometry tool =
      testing::TwoPlateDiscTool({{0, 0, 0}, {35, 0, 0}, {0, 28, 0}, {30, 40, 0}}, 200.0, 40.0);
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const std::vector<Eigen::Vector3d> normals = MarkerPlaneNormals(tool);
  ASSERT_EQ(normals.size(), 8u);
  for (std::size_t k = 0; k < 8; ++k) {
    const Eigen::Vector3d plate =
        k < 4 ? Eigen::Vector3d(Eigen::Vector3d::UnitZ()) : Eigen::Vector3d(turn.col(2));
    EXPECT_NEAR(std::abs(normals[k].dot(plate)), 1.0, kTolRad) << k;
  }
  constexpr double kFlatTolMm = 1e-6;  // the square root of a rounding-level eigenvalue
  for (const MarkerPlate& p : MarkerPlates(tool)) EXPECT_NEAR(p.flatness_rms_mm, 0.0, kFlatTolMm);
  // A marker lifted 8 mm off its plate: the four that define its plane are 3-4 mm off theirs
  // (rms of a 4-point plane fit of one point 8 mm up: 8 sqrt(3) / 4 / 2 = 1.7 mm).
  tool.markers_in_tool[3].z() = 8.0;
  EXPECT_GT(MarkerPlates(tool)[3].flatness_rms_mm, 1.0);
  tool.markers_in_tool[3].z() = 0.0;
  // One flat plate: every marker's normal is the plate's.
  tool.markers_in_tool.resize(4);
  for (const Eigen::Vector3d& n : MarkerPlaneNormals(tool)) {
    EXPECT_NEAR(std::abs(n.z()), 1.0, kTolRad);
  }
}

}  // namespace
}  // namespace tofnav
