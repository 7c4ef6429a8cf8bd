// SPDX-License-Identifier: BSD-3-Clause
// EVD plan on the phantom: entries on the skin at Kocher's point, targets in the frontal horns.
#include "tofnav/sim/evd_plan.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tofnav/sim/mesh_probe.hpp"
#include "tofnav/sim/patient.hpp"

namespace tofnav::sim {
namespace {

PatientHead TestHead() {
  HeadPhantomOptions options;
  options.segments = 96;  // coarse: fast in unoptimised builds
  return PhantomHead(options);
}

bool InsideEllipsoid(const Ellipsoid& e, const Eigen::Vector3d& p) {
  return (p - e.centre_in_image).cwiseQuotient(e.semi_axes_mm).norm() <= 1.0;
}

TEST(PlanEvdTrajectories, NineTrajectoriesFromKochersPointsToTheFrontalHorns) {
  const PatientHead head = TestHead();
  const std::vector<Trajectory> plan = PlanEvdTrajectories(head.skin_in_image, head.anatomy);
  ASSERT_EQ(plan.size(), 9u);
  const std::array<Ellipsoid, 2> ventricles = head.anatomy.Ventricles();
  const Eigen::Vector3d& c = head.anatomy.centre_in_image;
  for (const Trajectory& t : plan) {
    // The entry is a skin point: a ray from the centre through it meets the skin there.
    const MeshHit hit = RequireMeshHit(head.skin_in_image, c, t.entry_in_image - c, "entry");
    EXPECT_NEAR((hit.point - t.entry_in_image).norm(), 0.0, 1e-9) << t.name;
    EXPECT_TRUE(InsideEllipsoid(ventricles[0], t.target_in_image) ||
                InsideEllipsoid(ventricles[1], t.target_in_image))
        << t.name;
    const double depth_mm = (t.target_in_image - t.entry_in_image).norm();
    EXPECT_GT(depth_mm, 40.0) << t.name;  // EVD catheters reach 5-7 cm below the skin
    EXPECT_LT(depth_mm, 100.0) << t.name;
    EXPECT_GT(t.entry_in_image.z(), c.z() + 50.0) << t.name;  // on the upper skull (LPS +z)
  }
  // Side holes: about 3 cm lateral (LPS right = -x), ipsilateral targets.
  EXPECT_EQ(plan[0].name, "right-1");
  EXPECT_NEAR(plan[0].entry_in_image.x() - c.x(), -30.0, 6.0);
  EXPECT_TRUE(InsideEllipsoid(ventricles[0], plan[0].target_in_image));
  EXPECT_EQ(plan[3].name, "left-1");
  EXPECT_NEAR(plan[3].entry_in_image.x() - c.x(), 30.0, 6.0);
  EXPECT_TRUE(InsideEllipsoid(ventricles[1], plan[3].target_in_image));
  EXPECT_EQ(plan[6].name, "top-1");
  EXPECT_NEAR(plan[6].entry_in_image.x() - c.x(), -6.0, 3.0);
}

TEST(PlanEvdTrajectories, TheArcSetsHowFarBackTheEntryLies) {
  const PatientHead head = TestHead();
  EvdPlanOptions near, far;
  near.kocher_arc_mm = 90.0;
  far.kocher_arc_mm = 130.0;
  const double y_near =
      PlanEvdTrajectories(head.skin_in_image, head.anatomy, near)[0].entry_in_image.y();
  const double y_far =
      PlanEvdTrajectories(head.skin_in_image, head.anatomy, far)[0].entry_in_image.y();
  EXPECT_GT(y_far - y_near, 25.0);  // LPS +y is posterior; 40 mm more arc over the crown
}

}  // namespace
}  // namespace tofnav::sim
