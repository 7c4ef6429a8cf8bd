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

}  // namespace
}  // namespace tofnav
