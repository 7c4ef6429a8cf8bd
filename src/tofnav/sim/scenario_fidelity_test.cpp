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

// STTAR's protocol (docs/simulator.md 10.1): every hold's markers within 350-700 mm of depth, the
// second hold of a position the first moved 20 mm along the camera's z, the frame counts.
TEST(MarkerNoiseScenario, HoldsTheToolAt350To700MillimetresAndMovesIt20AlongZ) {
  constexpr double kSphereRadiusMm = 11.5 / 2.0;
  constexpr double kMaxToolExtentMm = 80.0;  // spheres-four: markers within 80 mm of each other
  MarkerNoiseProtocol protocol;
  protocol.positions = 7;
  protocol.frames_per_hold = 4;
  const Scenario s = MarkerNoiseScenario(protocol);
  ASSERT_NO_THROW(s.Check());
  EXPECT_EQ(s.frames, 2 * 7 * 4);
  EXPECT_EQ(s.timing.drop_probability, 0.0);
  ASSERT_EQ(s.scene.tools.size(), 1u);
  const Tool& tool = s.scene.tools[0];
  EXPECT_EQ(tool.name, kMarkerNoiseToolName);
  ASSERT_EQ(tool.markers.size(), 4u);
  for (const Marker& m : tool.markers) {
    EXPECT_EQ(m.shape, MarkerShape::kSphere);
    EXPECT_EQ(m.diameter_mm, 11.5);
    EXPECT_TRUE(s.scene.materials[static_cast<std::size_t>(m.material)].retro_reflective);
  }
  const std::vector<MarkerNoiseHold> holds = MarkerNoiseHolds(protocol);
  ASSERT_EQ(holds.size(), 14u);
  const Motion& mount = s.mounts[static_cast<std::size_t>(s.tool_mounts[0])].motion;
  double nearest_mm = 1e9, farthest_mm = 0.0;
  for (std::size_t h = 0; h < holds.size(); ++h) {
    const MarkerNoiseHold& hold = holds[h];
    EXPECT_EQ(hold.position, static_cast<int>(h / 2));
    EXPECT_EQ(hold.moved, h % 2 == 1);
    EXPECT_EQ(hold.first_slot, static_cast<std::int64_t>(h) * 4);
    EXPECT_EQ(hold.frames, 4);
    // Static over the hold, and where MarkerNoiseHolds says (the scene as rendered).
    for (std::int64_t k = 0; k < hold.frames; ++k) {
      const std::int64_t slot = hold.first_slot + k;
      const Rigid3d world_from_ahat = MotionPose(s.camera.motion, slot, s.timing.rate_hz, s.seed);
      const Rigid3d ahat_from_tool =
          world_from_ahat.Inverse() * MotionPose(mount, slot, s.timing.rate_hz, s.seed);
      EXPECT_LT(TranslationDistanceMm(ahat_from_tool, hold.ahat_from_tool), kExactMm);
      EXPECT_LT(RotationDistanceRad(ahat_from_tool, hold.ahat_from_tool), kExactMm);
    }
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Marker& m : tool.markers) {
      const Eigen::Vector3d c = hold.ahat_from_tool * m.centre_in_tool;
      centroid += c / 4.0;
      // Every sphere in front of the camera within its field (|x|, |y| < z) and near the range.
      EXPECT_LT(std::abs(c.x()), c.z());
      EXPECT_LT(std::abs(c.y()), c.z());
      EXPECT_GT(c.z(), protocol.min_depth_mm - kMaxToolExtentMm - kSphereRadiusMm);
      EXPECT_LT(c.z(), protocol.max_depth_mm + kMaxToolExtentMm + kSphereRadiusMm);
    }
    // The centroid's depth within 350-700 mm.
    EXPECT_GE(centroid.z(), protocol.min_depth_mm - kExactMm);
    EXPECT_LE(centroid.z(), protocol.max_depth_mm + kExactMm);
    nearest_mm = std::min(nearest_mm, centroid.z());
    farthest_mm = std::max(farthest_mm, centroid.z());
    if (hold.moved) {  // the same pose, 20 mm farther along the camera's z
      const Rigid3d& before = holds[h - 1].ahat_from_tool;
      const Eigen::Vector3d move = hold.ahat_from_tool.translation - before.translation;
      EXPECT_LT((move - Eigen::Vector3d(0.0, 0.0, 20.0)).norm(), kExactMm);
      EXPECT_LT(RotationDistanceRad(before, hold.ahat_from_tool), kExactMm);
    }
  }
  // Spread over the whole range: the nearest at 350 mm, the farthest at 700 mm.
  EXPECT_NEAR(nearest_mm, protocol.min_depth_mm, kExactMm);
  EXPECT_NEAR(farthest_mm, protocol.max_depth_mm, kExactMm);
  // Seeded: the same seed the same poses, another seed others.
  EXPECT_LT(
      TranslationDistanceMm(MarkerNoiseHolds(protocol)[6].ahat_from_tool, holds[6].ahat_from_tool),
      kExactMm);
  protocol.seed = 2;
  EXPECT_GT(
      TranslationDistanceMm(MarkerNoiseHolds(protocol)[6].ahat_from_tool, holds[6].ahat_from_tool),
      1.0);
}

}  // namespace
}  // namespace tofnav::sim
