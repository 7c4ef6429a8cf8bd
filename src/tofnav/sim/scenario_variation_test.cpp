// SPDX-License-Identifier: BSD-3-Clause
// Scenario variations change what they name and nothing else.
#include "tofnav/sim/scenario_variation.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "tofnav/core/require.hpp"
#include "tofnav/sim/evd_occluders.hpp"
#include "tofnav/sim/scenario_builtins.hpp"
#include "tofnav/sim/scenario_sanity.hpp"

namespace tofnav::sim {
namespace {

int CountReferences(const Scenario& s) {
  int n = 0;
  for (const Tool& t : s.scene.tools) n += t.name.starts_with("reference") ? 1 : 0;
  return n;
}

TEST(ScenarioVariation, SpheresSitOnPostsAboveTheSameLayout) {
  const Scenario before = BuiltinScenario("evd-usecase");
  Scenario after = before;
  ApplyVariation({.tools = ReferenceTools::kSpheres}, after);
  ASSERT_EQ(after.scene.tools.size(), before.scene.tools.size());
  for (std::size_t t = 0; t < after.scene.tools.size(); ++t) {
    const Tool& a = after.scene.tools[t];
    if (!a.name.starts_with("reference")) continue;
    for (std::size_t m = 0; m < a.markers.size(); ++m) {
      const Marker& disc = before.scene.tools[t].markers[m];
      const Marker& sphere = a.markers[m];
      EXPECT_EQ(sphere.shape, MarkerShape::kSphere);
      // Same point of the plate, 8 mm post plus the 5.75 mm radius above it (exact geometry).
      const Eigen::Vector3d rise = sphere.centre_in_tool - disc.centre_in_tool;
      EXPECT_NEAR(rise.cross(disc.normal_in_tool).norm(), 0.0, 1e-9);
      EXPECT_NEAR(rise.dot(disc.normal_in_tool), 8.0 + 5.75 - 0.1, 1e-9);  // discs float 0.1 mm
    }
  }
}

// The hand's keyframe at `slot` (world_from_mount).
Rigid3d HandAt(const Scenario& s, std::int64_t slot) {
  for (const Keyframe& k :
       s.mounts[static_cast<std::size_t>(s.FindMount("hand_motion"))].motion.keyframes) {
    if (k.slot == slot) return k.pose;
  }
  ADD_FAILURE() << "no hand keyframe at slot " << slot;
  return Rigid3d::Identity();
}

TEST(ScenarioVariation, TheHandPassesAboveSpheresOnPostsAtEverySlotTheFramesSpan) {
  Scenario tape = BuiltinScenario("evd-usecase");
  tape.frames = 90;  // the suite's short run: every 7th slot of 630
  tape.timing.slot_stride = 7;
  Scenario spheres = tape;
  ApplyVariation({.tools = ReferenceTools::kSpheres}, spheres);
  // Tape: the palm's axis 35 mm over reference_right, as placed (the discs stay clear of it).
  EXPECT_TRUE(FindMarkerIntersections(tape).empty());
  for (std::size_t t = 0; t < tape.scene.tools.size(); ++t) {
    if (tape.scene.tools[t].name != "reference_right") continue;
    const Rigid3d& mount_from_tool = tape.scene.tools[t].scene_from_tool;
    const Rigid3d& world_from_mount =
        tape.mounts[static_cast<std::size_t>(tape.tool_mounts[t])].motion.start;
    const Eigen::Vector3d normal = mount_from_tool.rotation * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d palm =
        (world_from_mount.Inverse() * HandAt(tape, kEvdHandReferenceSlot + 10)).translation -
        mount_from_tool.translation;
    EXPECT_NEAR(palm.dot(normal), 35.0, 1e-9);  // exact: the pose as built
  }
  // Spheres on posts (19.4 mm high) would reach 5-7 mm into the hovering hand at slot 460; the
  // pass is lifted along the plate's normal until none does (tolerance 0.5 mm, the check's own).
  const std::int64_t hover = kEvdHandReferenceSlot + 10;
  const Eigen::Vector3d lift = HandAt(spheres, hover).translation - HandAt(tape, hover).translation;
  EXPECT_GT(lift.norm(), 5.0);
  EXPECT_LT(lift.norm(), 15.0);
  EXPECT_EQ(HandAt(spheres, kEvdHandForeheadSlot).translation,
            HandAt(tape, kEvdHandForeheadSlot).translation);  // the other pass stays
  EXPECT_TRUE(FindMarkerIntersections(spheres).empty());
  // The same spheres under the unlifted hand: found at the hover's slot, which only the stride
  // brings within the 90 frames.
  Scenario unlifted = spheres;
  for (Keyframe& k : unlifted.mounts[static_cast<std::size_t>(unlifted.FindMount("hand_motion"))]
                         .motion.keyframes) {
    if (k.slot >= kEvdHandReferenceSlot && k.slot <= kEvdHandReferenceSlot + 34) {
      k.pose.translation -= lift;
    }
  }
  const std::vector<MarkerIntersection> found = FindMarkerIntersections(unlifted);
  ASSERT_FALSE(found.empty());
  EXPECT_GE(found.front().slot, kEvdHandReferenceSlot);
  EXPECT_GT(found.front().depth_mm, 3.0);
  unlifted.timing.slot_stride = 1;  // 90 frames of consecutive slots never reach the pass
  EXPECT_TRUE(FindMarkerIntersections(unlifted).empty());
}

TEST(ScenarioVariation, TheHandPassesAboveAPlateThatDriftsIntoItsPath) {
  // The suite's phantom-everything: spheres, and the patient drifting 1 mm/s obliquely, 10.5 mm
  // by the end of the hover (slot 474): lifted for the plate where it is then, not at slot 0.
  for (const ReferenceTools tools : {ReferenceTools::kSpheres, ReferenceTools::kAsBuilt}) {
    Scenario s = BuiltinScenario("evd-usecase");
    s.frames = 90;
    s.timing.slot_stride = 7;
    ApplyVariation({.tools = tools, .head_drift_mm_per_s = 1.0}, s);
    EXPECT_TRUE(FindMarkerIntersections(s).empty()) << static_cast<int>(tools);
  }
}

TEST(ScenarioVariation, TapeWithoutDriftLeavesEveryPassWhereItWas) {
  // Tolerance none: the passes are only moved where a marker would reach into them.
  const Scenario before = BuiltinScenario("evd-usecase");
  Scenario after = before;
  ApplyVariation({.surroundings = Surroundings::kPillow}, after);
  for (const char* mount : {"hand_motion", "instrument_motion"}) {
    const auto& a = after.mounts[static_cast<std::size_t>(after.FindMount(mount))].motion.keyframes;
    const auto& b =
        before.mounts[static_cast<std::size_t>(before.FindMount(mount))].motion.keyframes;
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k].pose.translation, b[k].pose.translation) << mount << " " << k;
    }
  }
}

TEST(ScenarioVariation, ASingleToolDropsTheOtherToolAndItsPlate) {
  Scenario s = BuiltinScenario("evd-usecase");
  ASSERT_EQ(CountReferences(s), 2);
  const std::string head_name = s.scene.objects[static_cast<std::size_t>(s.patient->object)].name;
  ApplyVariation({.tools = ReferenceTools::kSingleTool}, s);
  EXPECT_EQ(CountReferences(s), 1);
  EXPECT_EQ(s.FindObject("reference_right_plate"), -1);
  EXPECT_GE(s.FindObject("reference_left_plate"), 0);
  // The patient's skin is still the patient's object after the indices moved.
  EXPECT_EQ(s.scene.objects[static_cast<std::size_t>(s.patient->object)].name, head_name);
  EXPECT_EQ(s.tool_mounts.size(), s.scene.tools.size());
  EXPECT_EQ(s.object_mounts.size(), s.scene.objects.size());
}

TEST(ScenarioVariation, APillowLiesBehindTheHeadWithoutTouchingIt) {
  Scenario s = BuiltinScenario("evd-usecase");
  ApplyVariation({.surroundings = Surroundings::kPillow}, s);
  const int pillow = s.FindObject("pillow");
  ASSERT_GE(pillow, 0);
  const SceneObject& skin = s.scene.objects[static_cast<std::size_t>(s.patient->object)];
  const SceneObject& p = s.scene.objects[static_cast<std::size_t>(pillow)];
  double skin_back = -1e30, pillow_front = 1e30;
  for (const auto& v : skin.mesh.vertices)
    skin_back = std::max(skin_back, (skin.scene_from_object * v).y());
  for (const auto& v : p.mesh.vertices)
    pillow_front = std::min(pillow_front, (p.scene_from_object * v).y());
  EXPECT_GT(pillow_front - skin_back, 10.0);  // the 15 mm clearance, less the mesh's facets
  EXPECT_LT(pillow_front - skin_back, 20.0);
}

TEST(ScenarioVariation, DriftMovesThePatientSlowlyAndTimingAndJitterAreReplaced) {
  Scenario s = BuiltinScenario("evd-usecase");
  ApplyVariation({.head_drift_mm_per_s = 1.0,
                  .drop_probability = 0.05,
                  .mean_drop_slots = 3.0,
                  .slam_translation_sigma_mm = 1.0,
                  .slam_rotation_sigma_rad = 1e-3},
                 s);
  const Motion& m = s.mounts[static_cast<std::size_t>(
                                 s.object_mounts[static_cast<std::size_t>(s.patient->object)])]
                        .motion;
  const double moved_mm =
      (MotionPose(m, 450, 45.0, 0).translation - MotionPose(m, 0, 45.0, 0).translation).norm();
  EXPECT_NEAR(moved_mm, 10.0, 1e-6);  // 1 mm/s for 10 s
  EXPECT_EQ(s.timing.drop_probability, 0.05);
  EXPECT_EQ(s.timing.mean_drop_slots, 3.0);
  EXPECT_EQ(s.camera.slam.translation_sigma_mm, 1.0);
  EXPECT_THROW(ApplyVariation({.head_drift_mm_per_s = -1.0}, s), PreconditionError);
}

TEST(ScenarioVariation, SkinAndTheHeadsetsRangeChangeOnlyThePatientAndTheWearer) {
  const Scenario before = BuiltinScenario("evd-usecase");
  Scenario after = before;
  ApplyVariation(
      {.skin_albedo = 0.15, .headset_min_range_mm = 500.0, .headset_max_range_mm = 700.0}, after);
  const std::size_t head = static_cast<std::size_t>(after.patient->object);
  const Material& skin =
      after.scene.materials[static_cast<std::size_t>(after.scene.objects[head].material)];
  EXPECT_EQ(skin.name, "patient_skin");
  EXPECT_EQ(skin.albedo, 0.15);
  EXPECT_EQ(skin.subsurface_delay_ps, SkinMaterial().subsurface_delay_ps);
  for (std::size_t o = 0; o < after.scene.objects.size(); ++o) {
    if (o == head) continue;  // every other object keeps its material
    EXPECT_EQ(after.scene.objects[o].material, before.scene.objects[o].material) << o;
  }
  EXPECT_EQ(after.camera.motion.head_worn.min_range_mm, 500.0);
  EXPECT_EQ(after.camera.motion.head_worn.max_range_mm, 700.0);
  Scenario bad = before;
  EXPECT_THROW(ApplyVariation({.skin_albedo = 1.5}, bad), PreconditionError);
  EXPECT_THROW(ApplyVariation({.headset_min_range_mm = 800.0}, bad), PreconditionError);
}

TEST(ScenarioVariation, PerturbedDevicesStayWithinTheSpreadAndAreRepeatable) {
  const SyntheticAhatOptions base = CameraSetup().calibration;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const SyntheticAhatOptions d = PerturbedDevice(base, seed);
    EXPECT_LE(std::abs(d.focal_px / base.focal_px - 1.0), 0.02);
    EXPECT_LE((d.principal_point_px - base.principal_point_px).cwiseAbs().maxCoeff(), 4.0);
    const Rigid3d delta = base.rig_from_ahat.Inverse() * d.rig_from_ahat;
    EXPECT_LE(delta.translation.cwiseAbs().maxCoeff(), 2.0);
    EXPECT_LE(Eigen::AngleAxisd(delta.rotation).angle(), std::sqrt(3.0) * 0.0175);
    EXPECT_EQ(PerturbedDevice(base, seed).focal_px, d.focal_px);
  }
}

}  // namespace
}  // namespace tofnav::sim
