// SPDX-License-Identifier: BSD-3-Clause
// Coarse alignment of the phantom's face patch from arbitrary orientations.
#include "tofnav/registration/coarse_alignment.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numbers>

#include "matchers.hpp"
#include "registration_scenes.hpp"

namespace tofnav {
namespace {

// The coarse result must land in the fine ICP's basin (about 10-20 mm / 10-20 deg).
constexpr double kBasinRotRad = 5.0 * std::numbers::pi / 180.0;
constexpr double kBasinTransMm = 5.0;

class AlignCoarseOrientations : public testing::TestWithParam<double> {};

TEST_P(AlignCoarseOrientations, LandsInTheIcpBasin) {
  const TriangleMesh skin = test::PhantomSkin();
  const SurfaceIndex skin_in_image(skin);
  const Rigid3d tool_from_image(
      Eigen::Quaterniond(Eigen::AngleAxisd(GetParam(), Eigen::Vector3d(2, -1, 3).normalized())),
      Eigen::Vector3d(30.0, -250.0, 410.0));
  const SurfaceIndex face_in_tool(Transform(tool_from_image, test::FrontalVertices(skin)));
  const CoarseAlignResult r =
      AlignCoarse(face_in_tool, skin_in_image, test::FastTestOptions().coarse);
  ASSERT_TRUE(r.found());
  EXPECT_GT(r.hypotheses, 1000);
  EXPECT_THAT(r.candidates[0].target_from_source,
              RigidNear(tool_from_image.Inverse(), kBasinRotRad, kBasinTransMm));
  EXPECT_GT(r.candidates[0].score, 0.5);
  for (std::size_t i = 1; i < r.candidates.size(); ++i) {
    EXPECT_LE(r.candidates[i].score, r.candidates[i - 1].score);  // best first
  }
}

INSTANTIATE_TEST_SUITE_P(AnyAngle, AlignCoarseOrientations,
                         testing::Values(0.0, 0.5, 1.6, std::numbers::pi));

TEST(CoarseAlignOptions, CheckNamesTheField) {
  CoarseAlignOptions options;
  options.refine_gates_mm.clear();
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = {};
  options.score_samples = 8;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
