// SPDX-License-Identifier: BSD-3-Clause
// Built-in scenarios reproduce the paper's set-ups: counts, distances, angles, the patient.
#include "tofnav/sim/scenario_builtins.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numbers>

#include "tofnav/core/require.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/sim/mesh_probe.hpp"

namespace tofnav::sim {
namespace {

constexpr double kRateHz = 45.0;

// Pose of mount `name` seen from the camera at `slot`.
Rigid3d AhatFromMount(const Scenario& s, const std::string& name, std::int64_t slot) {
  const int mount = s.FindMount(name);
  EXPECT_GE(mount, 0) << name;
  const Rigid3d world_from_ahat = MotionPose(s.camera.motion, slot, kRateHz, 0);
  return world_from_ahat.Inverse() *
         MotionPose(s.mounts[static_cast<std::size_t>(mount)].motion, slot, kRateHz, 0);
}

TEST(BuiltinScenario, FrameCountsFollowThePaper) {
  const std::map<std::string, std::int64_t> frames = {
      {"marker-stage", 4 * 450},       {"materials", 15 * 6 * 250},
      {"head-identification", 1000},   {"depth-accuracy", 300},
      {"reconstruction", 2000},        {"evd-usecase", 2000},
      {"reconstruction-shapes", 2000}, {"reconstruction-shapes-pp", 2000},
      {"pivot-calibration", 450},      {"verify-landmarks", 568}};
  ASSERT_EQ(BuiltinScenarioNames().size(), frames.size());
  for (const auto& [name, count] : frames) {
    if (name == "head-identification" || name == "evd-usecase" || name == "reconstruction" ||
        name == "verify-landmarks") {
      continue;  // patient scenarios are checked (and timed) on their own below
    }
    const Scenario s = BuiltinScenario(name);
    EXPECT_NO_THROW(s.Check()) << name;
    EXPECT_EQ(s.name, name);
    EXPECT_EQ(s.frames, count) << name;
  }
  EXPECT_THROW(BuiltinScenario("no-such-scenario"), PreconditionError);
}

TEST(BuiltinScenario, MarkerStageRunsFrom300To700MmAtFourTilts) {
  const Scenario s = BuiltinScenario("marker-stage");
  for (int run = 0; run < 4; ++run) {
    const Rigid3d first = AhatFromMount(s, "stage", run * 450);
    const Rigid3d last = AhatFromMount(s, "stage", run * 450 + 449);
    EXPECT_NEAR(first.translation.z(), 300.0, 1e-6) << run;
    EXPECT_NEAR(last.translation.z(), 300.0 + 40.0 * 449.0 / kRateHz, 1e-6) << run;
    // Tilt: angle between the structure's normal and the optical axis.
    const double tilt = std::acos(-(first.rotation * Eigen::Vector3d::UnitZ()).z());
    EXPECT_NEAR(tilt, 10.0 * run * kDegToRad, 1e-9) << run;
  }
  EXPECT_EQ(s.scene.tools.at(0).markers.size(), 7u);
}

TEST(BuiltinScenario, MaterialsVisitFifteenDepthsAtSixAngles) {
  const Scenario s = BuiltinScenario("materials");
  for (const int station : {0, 14, 15, 89}) {
    const Rigid3d holder = AhatFromMount(s, "holder", station * 250 + 100);
    const double depth_mm = 382.0 + (655.0 - 382.0) * (station % 15) / 14.0;
    const double angle_rad = (5.0 + 8.0 * (station / 15)) * kDegToRad;
    EXPECT_NEAR(holder.translation.z(), depth_mm, 1e-6) << station;
    EXPECT_NEAR(std::acos(-(holder.rotation * Eigen::Vector3d::UnitZ()).z()), angle_rad, 1e-9);
  }
  for (const char* sample :
       {"nylon_sample", "pla_sample", "photopolymer_sample", "pc_abs_sample"}) {
    EXPECT_GE(s.FindObject(sample), 0) << sample;
  }
}

TEST(BuiltinScenario, EvdUseCaseHasTheHeadframeToolsStickersAndPlan) {
  const Scenario s = BuiltinScenario("evd-usecase");
  EXPECT_NO_THROW(s.Check());
  EXPECT_EQ(s.frames, 2000);
  ASSERT_TRUE(s.patient.has_value());
  EXPECT_EQ(s.patient->plan.size(), 9u);
  EXPECT_EQ(s.ToolsRigidWithPatient().size(), 3u);  // two references + the stickers
  EXPECT_EQ(s.camera.motion.kind, MotionKind::kHeadWorn);
  // The stickers are tape on the skin: 0.1 mm over the mean plane of the skin under them, which on
  // a convex head lies about half a 10 mm disc's sag (0.07 mm) below the skin at its centre.
  const TriangleMesh& skin = s.scene.objects[static_cast<std::size_t>(s.patient->object)].mesh;
  const sim::Tool& stickers = s.scene.tools[2];  // after the two references
  ASSERT_EQ(stickers.name, "forehead_markers");
  ASSERT_EQ(stickers.markers.size(), 3u);
  for (const Marker& m : stickers.markers) {
    const MeshHit hit = RequireMeshHit(skin, s.patient->anatomy.centre_in_image,
                                       m.centre_in_tool - s.patient->anatomy.centre_in_image, "");
    EXPECT_EQ(m.conforms_to_object, s.patient->object);
    EXPECT_LT((hit.point - m.centre_in_tool).norm(), 0.2);  // + the facets, along an oblique ray
  }
}

TEST(BuiltinScenario, HeadIdentificationHasFourForeheadMarkers) {
  const Scenario s = BuiltinScenario("head-identification");
  EXPECT_NO_THROW(s.Check());
  EXPECT_EQ(s.frames, 1000);
  ASSERT_EQ(s.ToolsRigidWithPatient().size(), 1u);
  EXPECT_EQ(s.scene.tools[0].markers.size(), 4u);
  EXPECT_EQ(s.scene.tools[0].markers[0].diameter_mm, 10.0);
}

TEST(BuiltinScenario, ReconstructionTurnsThePatientAndToolTogether) {
  const Scenario s = BuiltinScenario("reconstruction");
  EXPECT_NO_THROW(s.Check());
  EXPECT_EQ(s.frames, 2000);
  ASSERT_EQ(s.ToolsRigidWithPatient().size(), 1u);
  // The head surface stays 300-500 mm from the camera: its centre is about 400 mm away.
  for (const std::int64_t slot : {0, 500, 1000, 1500}) {
    const Rigid3d ahat_from_platform = AhatFromMount(s, "turntable", slot);
    const Rigid3d& platform_from_image =
        s.scene.objects[static_cast<std::size_t>(s.patient->object)].scene_from_object;
    const double range_mm = (ahat_from_platform * platform_from_image).translation.norm();
    EXPECT_GT(range_mm, 380.0);
    EXPECT_LT(range_mm, 420.0);
  }
}

}  // namespace
}  // namespace tofnav::sim
