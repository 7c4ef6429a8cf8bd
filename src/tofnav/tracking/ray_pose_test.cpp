// SPDX-License-Identifier: BSD-3-Clause
// PnP on rays: exact recovery from a perturbed start, blind to range errors.
#include "tofnav/tracking/ray_pose.hpp"

#include <gtest/gtest.h>

#include "matchers.hpp"
#include "tracking_test_tools.hpp"

namespace tofnav {
namespace {

TEST(EstimatePoseFromRays, RecoversThePoseFromRaysAloneDespiteBiasedStartingCentres) {
  constexpr double kRotTolRad = 1e-6, kTransTolMm = 1e-4;  // converged iteration
  const Points3d markers = {{-60, -40, 0}, {0, -45, 0}, {55, -35, 0}, {-50, 40, 0},
                            {5, 35, 0},    {60, 45, 0}, {10, 0, 0}};  // a planar structure
  const Rigid3d truth = testing::FacingToolPose({15.0, -20.0, 520.0}, 0.25, 0.4);
  Points3d rays, biased;
  for (const Eigen::Vector3d& m : markers) {
    const Eigen::Vector3d c = truth * m;
    rays.push_back(c.normalized());
    biased.push_back(c.normalized() * (c.norm() + 3.0));  // a 3 mm range error on every marker
  }
  Rigid3d start = testing::FacingToolPose({15.0, -20.0, 523.0}, 0.2, 0.45);
  const RayPoseResult r = EstimatePoseFromRays(markers, rays, start);
  ASSERT_TRUE(r.converged);
  EXPECT_THAT(r.ahat_from_tool, RigidNear(truth, kRotTolRad, kTransTolMm));
  EXPECT_LT(r.rms_ray_distance_mm, 1e-6);
  EXPECT_THROW(EstimatePoseFromRays(Points3d(2), Points3d(2), start), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
