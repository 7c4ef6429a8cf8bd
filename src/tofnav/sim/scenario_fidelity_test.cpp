// SPDX-License-Identifier: BSD-3-Clause
// The fidelity scenes: the skin spread's draws and the phantom facing the headset square on.
#include "tofnav/sim/scenario_fidelity.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tofnav/sim/motion.hpp"

namespace tofnav::sim {
namespace {

constexpr double kExactMm = 1e-6;  // poses built exactly: rounding only

TEST(SkinParticipant, DrawsTheSpreadReproducibly) {
  const SkinSpread spread;
  double sum = 0.0, sum2 = 0.0;
  constexpr int kDraws = 400;
  for (int i = 0; i < kDraws; ++i) {
    const Material m = SkinParticipant(7, i, spread);
    ASSERT_NO_THROW(m.Check());
    EXPECT_GE(m.albedo, spread.min_albedo);
    EXPECT_LE(m.albedo, spread.max_albedo);
    sum += m.subsurface_delay_ps;
    sum2 += m.subsurface_delay_ps * m.subsurface_delay_ps;
  }
  const double mean = sum / kDraws, sd = std::sqrt(sum2 / kDraws - mean * mean);
  // 400 normal draws: the mean within 4 standard errors (11 / 20 ps), the sd within 15 %.
  EXPECT_NEAR(mean, SkinMaterial().subsurface_delay_ps, 4.0 * spread.delay_sd_ps / 20.0);
  EXPECT_NEAR(sd, spread.delay_sd_ps, 0.15 * spread.delay_sd_ps);
  EXPECT_EQ(SkinParticipant(7, 3).subsurface_delay_ps, SkinParticipant(7, 3).subsurface_delay_ps);
  EXPECT_NE(SkinParticipant(7, 3).subsurface_delay_ps, SkinParticipant(8, 3).subsurface_delay_ps);
}

TEST(FacingPhantomScenario, TheHeadsetLooksAtTheForeheadFromTheGivenDistance) {
  const PatientHead head = PhantomHead();
  const Scenario s = FacingPhantomScenario(head, NylonMaterial(), 300.0, 30);
  ASSERT_NO_THROW(s.Check());
  EXPECT_EQ(s.frames, 30);
  EXPECT_EQ(s.timing.drop_probability, 0.0);
  const SceneObject& skin = s.scene.objects[static_cast<std::size_t>(s.patient->object)];
  EXPECT_EQ(s.scene.materials[static_cast<std::size_t>(skin.material)].name, "nylon");
  const Rigid3d world_from_image =
      MotionPose(s.mounts[static_cast<std::size_t>(s.object_mounts[s.patient->object])].motion, 0,
                 s.timing.rate_hz, s.seed) *
      skin.scene_from_object;
  const Rigid3d first = MotionPose(s.camera.motion, 0, s.timing.rate_hz, s.seed);
  const Rigid3d last = MotionPose(s.camera.motion, 29, s.timing.rate_hz, s.seed);
  EXPECT_LT(TranslationDistanceMm(first, last), kExactMm);  // static
  // The optical axis (+z) meets the skin 300 mm ahead, at the forehead.
  const Eigen::Vector3d axis_in_image =
      world_from_image.rotation.inverse() * (first.rotation * Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d eye_in_image = world_from_image.Inverse() * first.translation;
  const Eigen::Vector3d at = eye_in_image + 300.0 * axis_in_image;
  const MeshHit hit = head.Probe().RequireHit(at - head.anatomy.centre_in_image, "forehead");
  EXPECT_LT((hit.point - at).norm(), kExactMm);
  EXPECT_GT(at.z(), head.anatomy.centre_in_image.z());  // above the centre: the forehead
}

TEST(SkinStudyScenario, WearsTheHeadsetAt180To500Millimetres) {
  const Scenario s = SkinStudyScenario(PhantomHead(), SkinParticipant(1, 0), 50);
  ASSERT_NO_THROW(s.Check());
  EXPECT_EQ(s.camera.motion.head_worn.min_range_mm, 180.0);
  EXPECT_EQ(s.camera.motion.head_worn.max_range_mm, 500.0);
  EXPECT_EQ(s.frames, 50);
}

}  // namespace
}  // namespace tofnav::sim
