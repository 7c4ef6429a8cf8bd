// SPDX-License-Identifier: BSD-3-Clause
// Pose refinement: flat discs whose core pixels sit off-centre on a tilted plane.
#include "tofnav/tracking/pose_refinement.hpp"

#include <gtest/gtest.h>

#include "matchers.hpp"
#include "tofnav/markers/marker_centre.hpp"
#include "tracking_test_tools.hpp"

namespace tofnav {
namespace {

constexpr double kPixelPitchRad = 1.0 / 254.0;  // AHAT focal length

// A disc marker seen exactly, but with its core pixels only on one side of its centre (up to
// two pixels off): the face-on centre range t cos a then carries the tilted disc's range ramp.
DetectedMarker OffCentreDisc(const Eigen::Vector3d& centre, const Eigen::Vector3d& normal) {
  DetectedMarker d;
  d.ray_in_ahat = centre.normalized();
  d.pixel_pitch_rad = kPixelPitchRad;
  const Eigen::Vector3d across = d.ray_in_ahat.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d up = d.ray_in_ahat.cross(across);
  for (int i = 0; i <= 2; ++i) {
    for (int j = -1; j <= 1; ++j) {
      const Eigen::Vector3d u =
          (d.ray_in_ahat + kPixelPitchRad * (i * across + j * up)).normalized();
      const double t = normal.dot(centre) / normal.dot(u);  // the ray meets the disc plane
      d.core.push_back({static_cast<float>(t),
                        static_cast<float>(std::acos(std::min(1.0, u.dot(d.ray_in_ahat)))),
                        u.cast<float>()});
    }
  }
  std::vector<double> ranges;
  for (const CoreSample& s : d.core) ranges.push_back(s.range_mm);
  d.surface_range_mm = TrimmedMean(ranges);
  return d;
}

TEST(RefineToolPose, PlaneRangesRemoveTheRampOfOffCentreCoresOnATiltedTool) {
  constexpr double kRotTolRad = 1e-6, kTransTolMm = 1e-4;  // float rays and ranges
  ToolGeometry tool;
  tool.name = "flat";
  tool.marker_type = MarkerType::kDisc;
  tool.marker_diameter_mm = 10.0;
  tool.markers_in_tool = {{-35, -5, 0}, {30, 0, 0}, {5, -30, 0}, {-5, 42, 0}};
  const Rigid3d truth = testing::FacingToolPose({20.0, -10.0, 500.0}, 0.7, 0.3);
  const Eigen::Vector3d normal = truth.rotation * Eigen::Vector3d::UnitZ();
  std::vector<DetectedMarker> d;
  for (const Eigen::Vector3d& m : tool.markers_in_tool)
    d.push_back(OffCentreDisc(truth * m, normal));
  const Points3d centres = MarkerCentres(d, 0.0);
  const std::vector<int> index = {0, 1, 2, 3};
  const Rigid3d start = testing::FacingToolPose({21.0, -9.0, 502.0}, 0.68, 0.31);
  PoseRefinementOptions face_on;
  face_on.disc_plane_ranges = false;
  const std::optional<Rigid3d> plane = RefineToolPose(d, index, tool, centres, start);
  const std::optional<Rigid3d> ramp = RefineToolPose(d, index, tool, centres, start, face_on);
  ASSERT_TRUE(plane && ramp);
  EXPECT_THAT(*plane, RigidNear(truth, kRotTolRad, kTransTolMm));
  EXPECT_GT(RotationDistanceRad(*ramp, truth), 100.0 * kRotTolRad);  // the ramp's tilt
  d[2].pixel_pitch_rad = 0.0;  // hand-made detection: no refinement
  EXPECT_FALSE(RefineToolPose(d, index, tool, centres, start).has_value());
  face_on.passes = 0;
  EXPECT_THROW(RefineToolPose(d, index, tool, centres, start, face_on), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
