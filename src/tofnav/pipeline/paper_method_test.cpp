// SPDX-License-Identifier: BSD-3-Clause
// The paper's method's settings (issue 38 item 1): the hand placement's size and what each
// stage turns off.
#include "tofnav/pipeline/paper_method.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace tofnav {
namespace {

// The placement is built exactly (a rotation about the centre and a shift): only rounding.
constexpr double kExactMm = 1e-9;
constexpr double kExactRad = 1e-9;

Rigid3d Truth() {
  return {Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.3, 1.0, -0.2).normalized())),
          Eigen::Vector3d(10.0, -250.0, 80.0)};
}

TEST(PaperMethod, NamesRoundTrip) {
  EXPECT_EQ(ParseMethod("paper"), Method::kPaper);
  EXPECT_EQ(ParseMethod("tofnav"), Method::kTofnav);
  EXPECT_FALSE(ParseMethod("Paper").has_value());
  EXPECT_STREQ(ToString(*ParseMethod(ToString(Method::kPaper))), "paper");
}

TEST(PaperMethod, HandPlacementIsFiveMillimetresAndFiveDegreesOffAtTheCentre) {
  const Eigen::Vector3d centre(5.0, 20.0, -30.0);
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const Rigid3d start = HandPlacedStart(Truth(), centre, seed);
    // The skin's centre moves by the translation alone; the whole turns by the rotation.
    EXPECT_NEAR((start * centre - Truth() * centre).norm(), 5.0, kExactMm) << seed;
    EXPECT_NEAR(RotationDistanceRad(start, Truth()), 5.0 * std::numbers::pi / 180.0, kExactRad)
        << seed;
  }
  EXPECT_NEAR(
      RotationDistanceRad(HandPlacedStart(Truth(), centre, 7), HandPlacedStart(Truth(), centre, 7)),
      0.0, kExactRad);
  // Another seed, another direction: the two starts differ by more than rounding.
  EXPECT_GT(TranslationDistanceMm(HandPlacedStart(Truth(), centre, 7),
                                  HandPlacedStart(Truth(), centre, 8)),
            0.1);
}

TEST(PaperMethod, IdentificationIsEquationThreeWithoutTofnavsAdditions) {
  IdentifyRecordingOptions o;
  o.max_frames = 123;
  o.exclude_tools.resize(2);
  o.reference_tool.emplace();
  UsePaperIdentification(o);
  EXPECT_EQ(o.max_frames, 123);  // kept
  EXPECT_FALSE(o.start.use_intensity);
  EXPECT_TRUE(o.start.use_range_term);
  EXPECT_EQ(o.start.angle_term, AngleTerm::kTheta);
  EXPECT_FALSE(o.start.multipath.enabled);
  EXPECT_EQ(o.start.cyclic.amplitude_mm, 0.0);
  EXPECT_TRUE(o.exclude_tools.empty());
  EXPECT_FALSE(o.reference_tool.has_value());
  EXPECT_EQ(o.placement_subsets, 0);
  EXPECT_FALSE(o.sampling.segmentation.head_region.enabled);
  EXPECT_FALSE(o.sampling.multipath.enabled);
  EXPECT_EQ(o.identification.huber_scale_mm, 0.0);
  EXPECT_FALSE(o.identification.reject_outlier_markers);
  EXPECT_FALSE(o.identification.foreground.enabled);
  EXPECT_EQ(o.identification.fit_cyclic_period_mm, 0.0);
  EXPECT_NO_THROW(o.identification.Check());
  EXPECT_NO_THROW(o.sampling.Check());
}

TEST(PaperMethod, TrackingReconstructionAndRegistrationHaveNoChecks) {
  ReconstructOptions r;
  UsePaperReconstruction(r);
  EXPECT_FALSE(r.check_pose_consistency);
  EXPECT_FALSE(r.smooth_rotation);
  EXPECT_FALSE(r.model_check.enabled);
  EXPECT_FALSE(r.head_region.enabled);
  EXPECT_EQ(r.boundary_rings_removed, 0);
  EXPECT_EQ(r.pose.tolerance.AtMm(300.0), 4.0);
  EXPECT_EQ(r.pose.tolerance.AtMm(700.0), 4.0);
  EXPECT_FALSE(r.pose.refinement.enabled);
  EXPECT_NO_THROW(r.Check());

  NavigatorOptions n;
  UsePaperTracking(n);
  EXPECT_FALSE(n.tracking.filter_enabled);
  EXPECT_FALSE(n.check_pose_jumps);
  EXPECT_EQ(n.tracking.pose.prior_weight, 0.0);
  EXPECT_NO_THROW(n.Check());

  RegisterSurfaceOptions g;
  UsePaperRegistration(g);
  EXPECT_EQ(g.icp.loss, RobustLoss::kSquared);
  ASSERT_EQ(g.icp.max_distance_schedule_mm.size(), 1u);
  EXPECT_NO_THROW(g.Check());
}

}  // namespace
}  // namespace tofnav
