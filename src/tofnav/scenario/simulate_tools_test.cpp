// SPDX-License-Identifier: BSD-3-Clause
// tofnav simulate writes tools/<tool>.json with the scene's marker geometry (docs/simulator.md).
#include <gtest/gtest.h>

#include "simulate_test_helpers.hpp"
#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/io/io_test_helpers.hpp"
#include "tofnav/scenario/simulate.hpp"
#include "tofnav/sim/tool_presets.hpp"

namespace tofnav {
namespace {

TEST(RunSimulation, WritesAToolFileForEveryTrackableTool) {
  sim::Scenario s;
  s.name = "tools";
  const int retro = s.scene.AddMaterial(sim::RetroReflectiveMaterial());
  s.AddTool(sim::ToolPreset("reference-a", "ref_a", retro), -1);
  s.AddTool(sim::ToolPreset("tape-seven", "tape", retro), -1);
  sim::Tool pair{"pair", {}, Rigid3d()};  // two markers: no pose possible, no file
  pair.markers = {sim::SphereMarker({0, 0, 0}, 10.0, retro),
                  sim::SphereMarker({50, 0, 0}, 10.0, retro)};
  s.AddTool(pair, -1);
  s.camera.motion = sim::StaticMotion(Rigid3d(Eigen::Quaterniond::Identity(), {0, 0, -400}));
  s.render.supersampling = 1;
  s.render.window = {0, 0, 16, 16};
  SimulateOptions options;
  options.frames = 1;
  options.camera = testing::SharedCamera();
  const testing::TempDir dir("simulate_tools");
  const SimulateResult result = RunSimulation(s, dir.path(), options);

  for (const sim::Tool& t : s.scene.tools) {
    const std::filesystem::path file = dir.path() / "tools" / (t.name + ".json");
    if (t.name == "pair") {
      EXPECT_FALSE(std::filesystem::exists(file));
      continue;
    }
    const ToolGeometry tool = ReadToolJson(file);
    EXPECT_EQ(tool.name, t.name);
    ASSERT_EQ(tool.markers_in_tool.size(), t.markers.size());
    for (std::size_t i = 0; i < t.markers.size(); ++i) {
      EXPECT_EQ(tool.markers_in_tool[i], t.markers[i].centre_in_tool) << t.name << " " << i;
    }
    EXPECT_EQ(tool.marker_diameter_mm, t.markers[0].diameter_mm);
    EXPECT_EQ(tool.marker_type, t.markers[0].shape == sim::MarkerShape::kDisc
                                    ? MarkerType::kDisc
                                    : MarkerType::kSphere);
    EXPECT_NE(std::find(result.files.begin(), result.files.end(),
                        std::filesystem::path("tools/" + t.name + ".json")),
              result.files.end());
  }
  EXPECT_EQ(testing::ReadJson(dir.path() / "truth.json").at("files").at("tool:tape"),
            "tools/tape.json");
}

}  // namespace
}  // namespace tofnav
