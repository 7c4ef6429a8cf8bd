// SPDX-License-Identifier: BSD-3-Clause
// Pose refinement: flat discs whose core pixels sit off-centre on a tilted plane.
#include "tofnav/tracking/pose_refinement.hpp"

#include <gtest/gtest.h>

#include <utility>

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

// The pose refined from `start` with the discs' plate ranges (the default) and with their face-on
// ranges (disc_plane_ranges off), both required to converge.
std::pair<Rigid3d, Rigid3d> RefineBothWays(const std::vector<DetectedMarker>& d,
                                           const ToolGeometry& tool, const Rigid3d& start) {
  const Points3d centres = MarkerCentres(d, 0.0);
  std::vector<int> index(d.size());
  for (std::size_t k = 0; k < d.size(); ++k) index[k] = static_cast<int>(k);
  PoseRefinementOptions face_on;
  face_on.disc_plane_ranges = false;
  const std::optional<Rigid3d> plane = RefineToolPose(d, index, tool, centres, start);
  const std::optional<Rigid3d> ramp = RefineToolPose(d, index, tool, centres, start, face_on);
  EXPECT_TRUE(plane && ramp);
  return {plane.value_or(Rigid3d()), ramp.value_or(Rigid3d())};
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
  const Rigid3d start = testing::FacingToolPose({21.0, -9.0, 502.0}, 0.68, 0.31);
  const auto [plane, ramp] = RefineBothWays(d, tool, start);
  EXPECT_THAT(plane, RigidNear(truth, kRotTolRad, kTransTolMm));
  EXPECT_GT(RotationDistanceRad(ramp, truth), 100.0 * kRotTolRad);  // the ramp's tilt
  const Points3d centres = MarkerCentres(d, 0.0);
  const std::vector<int> index = {0, 1, 2, 3};
  d[2].pixel_pitch_rad = 0.0;  // hand-made detection: no refinement
  EXPECT_FALSE(RefineToolPose(d, index, tool, centres, start).has_value());
  PoseRefinementOptions no_pass;
  no_pass.passes = 0;
  EXPECT_THROW(RefineToolPose(d, index, tool, centres, start, no_pass), std::invalid_argument);
}

// A headframe's two flat plates tracked as one disc tool (not planar as a whole): each disc's
// range is carried along its own plate, and the pose comes out exact; the old rule (the whole
// tool's plane, or none when the tool is not flat) kept the ramp's error.
TEST(RefineToolPose, PlaneRangesFollowEachPlateOfATwoPlateTool) {
  // float rays and ranges, and two passes each taking the plates at the previous pose
  constexpr double kRotTolRad = 1e-5, kTransTolMm = 1e-3;
  const ToolGeometry tool =
      testing::TwoPlateDiscTool({{-35, -5, 0}, {30, 0, 0}, {5, -30, 0}, {-5, 42, 0}}, 160.0, 40.0);
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Rigid3d truth = testing::FacingToolPose({-60.0, -10.0, 550.0}, 0.5, 0.2);
  std::vector<DetectedMarker> d;
  for (std::size_t k = 0; k < 8; ++k) {
    const Eigen::Vector3d plate = k < 4 ? Eigen::Vector3d(Eigen::Vector3d::UnitZ()) : turn.col(2);
    d.push_back(OffCentreDisc(truth * tool.markers_in_tool[k], truth.rotation * plate));
  }
  const Rigid3d start = testing::FacingToolPose({-59.0, -9.0, 552.0}, 0.48, 0.21);
  const auto [plates, ramp] = RefineBothWays(d, tool, start);
  EXPECT_THAT(plates, RigidNear(truth, kRotTolRad, kTransTolMm));
  EXPECT_GT((ramp.translation - truth.translation).norm(), 30.0 * kTransTolMm);
  EXPECT_GT(RotationDistanceRad(ramp, truth), 30.0 * kRotTolRad);
}

}  // namespace
}  // namespace tofnav
