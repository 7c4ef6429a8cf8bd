// SPDX-License-Identifier: BSD-3-Clause
// The frame loop: timestamps of kept slots, reported vs true poses, truth poses and pixels.
#include "tofnav/sim/simulator.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "matchers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/sim/shapes.hpp"
#include "tofnav/sim/tool_presets.hpp"

namespace tofnav::sim {
namespace {

constexpr double kExactRad = 1e-12, kExactMm = 1e-9;  // compositions of exact poses

// A board with a six-marker tool on a stage 400 mm in front of a fixed camera; only a window
// around the image centre is rendered (fast in unoptimised builds).
Scenario StageScenario() {
  Scenario s;
  s.name = "test-stage";
  s.frames = 3;
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial());
  const int board = s.scene.AddMaterial(DiffuseMaterial(0.5));
  const Eigen::Vector3d eye(0.0, 0.0, 0.0), centre(0.0, 0.0, -400.0);
  s.camera.motion = StaticMotion(LookAt(eye, centre));
  const int stage =
      s.AddMount("stage", LinearStageMotion(LookAt(centre, eye), {1.0, 0.0, 0.0}, 45.0, 100.0));
  s.AddObject("board", PlaneMesh(200.0, 200.0), board, stage, Rigid3d::Identity());
  s.AddTool(ToolPreset("planar-six", "tool", retro), stage);
  s.render = IdealRenderOptions();
  s.render.window = {192, 192, 128, 128};
  s.timing.drop_probability = 0.9;
  return s;
}

// Built once per test binary: the camera model is slow to build unoptimised.
std::shared_ptr<const SimulatorCamera> SharedCamera() {
  static const auto camera = std::make_shared<const SimulatorCamera>(CameraSetup().calibration);
  return camera;
}

TEST(Simulator, FramesCarryTheirSlotTimesPosesAndTruth) {
  const Scenario s = StageScenario();
  Simulator simulator(s, SharedCamera());
  std::int64_t previous_slot = -1;
  while (!simulator.done()) {
    const SimulatedFrame f = simulator.Next();
    EXPECT_GT(f.slot, previous_slot);
    previous_slot = f.slot;
    EXPECT_EQ(f.render.frame.host_ticks, SlotTicks(s.timing, f.slot));
    // The true rig pose composes with rig_from_ahat to the camera pose; the reported one is
    // within a few sigma of SLAM jitter.
    const Rigid3d world_from_ahat = ScenarioCameraPose(s, f.slot);
    EXPECT_THAT(f.world_from_rig_true * s.camera.calibration.rig_from_ahat,
                RigidNear(world_from_ahat, 1e-9, 1e-6));
    EXPECT_THAT(*f.render.frame.world_from_rig, RigidNear(f.world_from_rig_true, 5e-3, 3.0));
    // The stage moves 1 mm per slot along world x = the camera's x (it looks along -z, y up).
    const Rigid3d& ahat_from_tool = f.ahat_from_tools[0];
    EXPECT_NEAR(ahat_from_tool.translation.x(), static_cast<double>(f.slot), kExactMm);
    EXPECT_THAT(f.ahat_from_objects[0], RigidNear(ahat_from_tool, kExactRad, kExactMm));
    // Visible marker centres project where the truth image shows that marker.
    int visible = 0;
    for (std::size_t m = 0; m < f.render.markers.size(); ++m) {
      const MarkerTruth& marker = f.render.markers[m];
      if (marker.pixel_count == 0) continue;
      ++visible;
      ASSERT_TRUE(f.marker_pixels[m].has_value());
      const int u = static_cast<int>(std::lround(f.marker_pixels[m]->x()));
      const int v = static_cast<int>(std::lround(f.marker_pixels[m]->y()));
      EXPECT_EQ(f.render.truth_marker(u, v), marker.id);
      EXPECT_GT(f.render.frame.ab(u, v), 1000);  // retro-reflective: far above skin or board
    }
    EXPECT_EQ(visible, 6);
  }
  EXPECT_EQ(previous_slot, 2 + simulator.dropped_slots());
  EXPECT_GT(simulator.dropped_slots(), 0);  // p = 0.9 over two draws with this seed
  EXPECT_THROW(simulator.Next(), PreconditionError);
}

TEST(Simulator, TheSeedDecidesEverything) {
  Scenario s = StageScenario();
  s.render = RenderOptions();  // noise on
  s.render.supersampling = 1;
  s.render.window = {224, 224, 64, 64};
  Simulator a(s, SharedCamera()), b(s, SharedCamera());
  s.seed = 2;
  Simulator c(s, SharedCamera());
  const SimulatedFrame fa = a.Next(), fb = b.Next(), fc = c.Next();
  EXPECT_EQ(fa.render.frame.range_mm, fb.render.frame.range_mm);
  EXPECT_EQ(fa.render.frame.ab, fb.render.frame.ab);
  EXPECT_THAT(*fa.render.frame.world_from_rig,
              RigidNear(*fb.render.frame.world_from_rig, 0.0, 0.0));
  EXPECT_NE(fa.render.frame.ab, fc.render.frame.ab);
}

TEST(Simulator, RefusesACameraBuiltForOtherOptions) {
  Scenario s = StageScenario();
  s.camera.calibration.focal_px = 250.0;
  EXPECT_THROW(Simulator(s, SharedCamera()), PreconditionError);
}

}  // namespace
}  // namespace tofnav::sim
