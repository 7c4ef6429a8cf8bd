// SPDX-License-Identifier: BSD-3-Clause
// verify-landmarks: the pointer's true tip rests on each landmark for its touch slots.
#include "tofnav/sim/scenario_verify.hpp"

#include <gtest/gtest.h>

#include "tofnav/sim/scenario_builtins.hpp"

namespace tofnav::sim {
namespace {

constexpr double kRateHz = 45.0;

const Mount& Named(const Scenario& s, const std::string& name) {
  return s.mounts.at(static_cast<std::size_t>(s.FindMount(name)));
}

TEST(VerifyLandmarksScenario, ThePointersTipRestsOnEachLandmarkOnTheSkin) {
  const Scenario s = BuiltinScenario("verify-landmarks");
  ASSERT_NO_THROW(s.Check());
  EXPECT_EQ(s.frames, 568);
  ASSERT_TRUE(s.patient.has_value());
  ASSERT_EQ(s.patient->landmarks.size(), 4u);
  const Tool* pointer = nullptr;
  for (const Tool& t : s.scene.tools) {
    if (t.name == "instrument") pointer = &t;
  }
  ASSERT_NE(pointer, nullptr);
  ASSERT_TRUE(pointer->tip_in_tool.has_value());
  const SceneObject& skin = s.scene.objects[static_cast<std::size_t>(s.patient->object)];
  const Rigid3d world_from_image =
      Named(s, "headframe").motion.start * skin.scene_from_object;  // mount_from_image
  const PatientHead head = PhantomHead();
  std::int64_t previous_last = -1;
  for (const PlannedLandmark& l : s.patient->landmarks) {
    SCOPED_TRACE(l.name);
    // On the skin: the ray from the anatomy centre leaves it there.
    const MeshHit hit = head.Probe().RequireHit(l.in_image - head.anatomy.centre_in_image, "l");
    EXPECT_LT((hit.point - l.in_image).norm(), 1e-9);
    ASSERT_GT(l.touch_first_slot, previous_last);
    EXPECT_EQ(l.touch_last_slot - l.touch_first_slot, 72);  // 1.6 s at 45 Hz
    previous_last = l.touch_last_slot;
    for (std::int64_t slot = l.touch_first_slot; slot <= l.touch_last_slot; slot += 8) {
      const Rigid3d world_from_pointer =
          MotionPose(Named(s, "instrument_motion").motion, slot, kRateHz, s.seed) *
          pointer->scene_from_tool;
      // Exact up to the keyframe interpolation's rounding.
      EXPECT_LT((world_from_pointer * *pointer->tip_in_tool - world_from_image * l.in_image).norm(),
                1e-6)
          << slot;
      // The markers lean away from the skin: well outside the head.
      const Eigen::Vector3d markers = world_from_pointer * pointer->markers.front().centre_in_tool;
      EXPECT_GT((world_from_image.Inverse() * markers - head.anatomy.centre_in_image).norm(),
                (l.in_image - head.anatomy.centre_in_image).norm() + 100.0);
    }
  }
  EXPECT_LT(previous_last, s.frames);
}

}  // namespace
}  // namespace tofnav::sim
