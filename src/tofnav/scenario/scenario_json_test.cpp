// SPDX-License-Identifier: BSD-3-Clause
// Scenario JSON: defaults, every part of the schema, strictness (unknown keys, types, values).
#include "tofnav/scenario/scenario_json.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numbers>
#include <string>

#include "matchers.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/io_test_helpers.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/sim/shapes.hpp"

namespace tofnav {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

sim::Scenario Parse(const std::string& text) { return ParseScenarioJson(text, "test.json"); }

void ExpectError(const std::string& text, const std::string& message) {
  EXPECT_THAT([&] { Parse(text); }, ThrowsMessage<IoError>(HasSubstr(message))) << text;
}

TEST(ParseScenarioJson, AnEmptyObjectGivesTheDefaults) {
  const sim::Scenario s = Parse("{}");
  EXPECT_EQ(s.name, "custom");
  EXPECT_EQ(s.frames, 100);
  EXPECT_EQ(s.seed, 1u);
  EXPECT_TRUE(s.scene.objects.empty());
  EXPECT_EQ(s.timing.rate_hz, 45.0);
  EXPECT_EQ(s.render.supersampling, 2);
  EXPECT_FALSE(s.patient.has_value());
  EXPECT_THAT(s.camera.calibration.rig_from_ahat, RigidNear(TypicalRigFromAhat(), 0.0, 0.0));
}

// A document using every part of the schema (docs/simulator.md), with a small phantom.
constexpr const char* kFull = R"({
  "name": "bench-test", "description": "all parts", "seed": 9, "frames": 12,
  "materials": [{"name": "grey", "preset": "diffuse", "albedo": 0.3},
                {"name": "tape", "preset": "retro_reflective", "retro_curve": "sigmoid",
                 "retro_curve_amplitude_mm": 3.0}],
  "mounts": [{"name": "stage", "motion": {"kind": "linear", "start": {"translation_mm": [0, 0, -400]},
              "direction": [0, 0, -1], "speed_mm_per_s": 20, "travel_mm": 200}},
             {"name": "steps", "motion": {"kind": "sequence", "segments": [
               {"kind": "static", "pose": {"translation_mm": [1, 2, 3]}, "slots": 5},
               {"kind": "rotation", "axis": [0, 1, 0], "speed_rad_per_s": 0.1, "slots": 7}]}}],
  "patient": {"head": "phantom", "phantom": {"segments": 48}, "material": "nylon",
              "mount": "steps", "pose": {"rotation_vector_rad": [0, 3.141592653589793, 0]},
              "ct": {"spacing_mm": 2.5, "noise_sigma_hu": 5, "write": false},
              "plan": {"kocher_lateral_mm": 25}},
  "objects": [{"name": "board", "shape": {"kind": "plane", "width_mm": 300, "height_mm": 200},
               "material": "grey", "mount": "stage"},
              {"name": "cone", "shape": {"kind": "test_shape", "shape": "frustum_pyramid", "size_mm": 60},
               "material": "pla", "pose": {"look_at": {"eye_mm": [0, 0, 0], "target_mm": [0, 0, 1]}}}],
  "tools": [{"name": "six", "preset": "planar-six", "material": "tape", "mount": "stage",
             "plate_material": "grey", "pose": {"translation_mm": [0, 50, 0.5]}},
            {"name": "custom_tool", "markers": [{"shape": "sphere", "diameter_mm": 11.5, "centre_mm": [0, 0, 5]},
                                               {"shape": "disc", "centre_mm": [40, 0, 0], "normal": [0, 0, 2]}]},
            {"name": "stickers", "stickers": {"azimuth_elevation_rad": [[0.1, 0.5], [-0.2, 0.6]]}}],
  "camera": {"motion": {"kind": "head_worn", "target_mm": [0, 0, -400], "min_range_mm": 350},
             "calibration": {"focal_px": 250, "principal_point_px": [255, 254]},
             "slam_jitter": {"translation_sigma_mm": 0.1}},
  "timing": {"rate_hz": 30, "drop_probability": 0.05, "start_ticks": 1000},
  "render": {"preset": "model_consistent", "supersampling": 3, "noise": {"depth_sigma_ref_mm": 2},
             "sensor": {"floor_depth": true}}
})";

TEST(ParseScenarioJson, StickersAreTapeUnlessTheyAreSaidNotToConform) {
  const std::string head = R"({"patient": {"head": "phantom"}, "tools": [{"name": "s", "stickers":
      {"azimuth_elevation_rad": [[0.1, 0.5]], "conform": )";
  EXPECT_EQ(Parse(head + "true}}]}").scene.tools[0].markers[0].conforms_to_object,
            Parse(head + "true}}]}").patient->object);
  EXPECT_EQ(Parse(head + "false}}]}").scene.tools[0].markers[0].conforms_to_object, -1);
  ExpectError(head + "3}}]}", "conform");
}

TEST(ParseScenarioJson, ReadsEveryPartOfTheSchema) {
  const sim::Scenario s = Parse(kFull);
  EXPECT_EQ(s.name, "bench-test");
  EXPECT_EQ(s.seed, 9u);
  EXPECT_EQ(s.frames, 12);
  // Materials: two declared, then presets named by objects added on first use.
  ASSERT_GE(s.scene.materials.size(), 4u);
  EXPECT_EQ(s.scene.materials[0].albedo, 0.3);
  EXPECT_EQ(s.scene.materials[1].retro_curve, sim::RetroCurve::kSigmoid);
  EXPECT_TRUE(s.scene.materials[1].retro_reflective);
  EXPECT_GE(s.FindMaterial("nylon"), 0);
  EXPECT_GE(s.FindMaterial("pla"), 0);
  // Mounts and motions.
  ASSERT_EQ(s.mounts.size(), 2u);
  EXPECT_EQ(s.mounts[0].motion.kind, sim::MotionKind::kLinear);
  EXPECT_EQ(s.mounts[0].motion.linear.speed_mm_per_s, 20.0);
  ASSERT_EQ(s.mounts[1].motion.segments.size(), 2u);
  EXPECT_EQ(s.mounts[1].motion.segments[0].segment_slots, 5);
  EXPECT_EQ(s.mounts[1].motion.segments[1].kind, sim::MotionKind::kRotation);
  // The patient: head object first, on its mount, with the plan and CT options.
  ASSERT_TRUE(s.patient.has_value());
  EXPECT_EQ(s.scene.objects[static_cast<std::size_t>(s.patient->object)].name, "head");
  EXPECT_EQ(s.object_mounts[static_cast<std::size_t>(s.patient->object)], 1);
  EXPECT_FALSE(s.patient->write_ct);
  EXPECT_EQ(s.patient->ct.spacing_mm, 2.5);
  EXPECT_EQ(s.patient->plan.size(), 9u);
  // Objects, including the preset tool's plate.
  EXPECT_GE(s.FindObject("board"), 0);
  EXPECT_GE(s.FindObject("six_plate"), 0);
  const sim::SceneObject& cone = s.scene.objects[static_cast<std::size_t>(s.FindObject("cone"))];
  EXPECT_EQ(s.object_mounts[static_cast<std::size_t>(s.FindObject("cone"))], -1);
  EXPECT_NEAR((cone.scene_from_object.rotation * Eigen::Vector3d::UnitZ()).z(), 1.0, 1e-12);
  // Tools: preset, explicit markers (normal normalised), stickers on the patient's mount.
  ASSERT_EQ(s.scene.tools.size(), 3u);
  EXPECT_EQ(s.scene.tools[0].markers.size(), 6u);
  EXPECT_EQ(s.scene.tools[0].scene_from_tool.translation.y(), 50.0);
  EXPECT_EQ(s.scene.tools[1].markers[0].shape, sim::MarkerShape::kSphere);
  EXPECT_EQ(s.scene.tools[1].markers[1].normal_in_tool, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(s.scene.tools[2].markers.size(), 2u);
  EXPECT_EQ(s.scene.tools[2].markers[0].conforms_to_object, s.patient->object);  // tape
  EXPECT_EQ(s.tool_mounts[2], 1);
  EXPECT_EQ(s.ToolsRigidWithPatient(), std::vector<int>{2});
  // Camera, timing, render.
  EXPECT_EQ(s.camera.motion.kind, sim::MotionKind::kHeadWorn);
  EXPECT_EQ(s.camera.motion.head_worn.min_range_mm, 350.0);
  EXPECT_EQ(s.camera.calibration.focal_px, 250.0);
  EXPECT_EQ(s.camera.slam.translation_sigma_mm, 0.1);
  EXPECT_EQ(s.timing.rate_hz, 30.0);
  EXPECT_EQ(s.timing.start_ticks, 1000u);
  EXPECT_EQ(s.render.bias_mode, sim::BiasMode::kModel);
  EXPECT_EQ(s.render.supersampling, 3);
  EXPECT_EQ(s.render.noise.depth_sigma_ref_mm, 2.0);
  EXPECT_TRUE(s.render.sensor.floor_depth);
}

TEST(ParseScenarioJson, UnknownKeysAreErrorsWithTheirPath) {
  ExpectError(R"({"frame": 3})", "$: unknown key(s) 'frame'");
  ExpectError(R"({"objects": [{"name": "b", "shape": {"kind": "plane", "widht_mm": 3}}]})",
              "$.objects[0].shape: unknown key(s) 'widht_mm'");
  ExpectError(R"({"render": {"noise": {"sigma": 1}}})", "$.render.noise: unknown key(s) 'sigma'");
  ExpectError(R"({"camera": {"motion": {"kind": "static", "start": {}}}})",
              "$.camera.motion: unknown key(s) 'start'");
}

TEST(ParseScenarioJson, WrongTypesAndValuesAreErrors) {
  ExpectError(R"({"frames": "many"})", "$.frames: expected an integer");
  ExpectError(R"({"frames": 0})", "Scenario.frames must be >= 1");
  ExpectError(R"({"timing": {"drop_probability": 2}})", "$.timing: ");
  ExpectError(R"({"mounts": [{"name": "m", "motion": {"kind": "warp"}}]})",
              "unknown motion 'warp'");
  ExpectError(R"({"objects": [{"name": "b", "shape": {"kind": "plane"}, "material": "gold"}]})",
              "no material or preset called 'gold'");
  ExpectError(R"({"objects": [{"name": "b", "shape": {"kind": "plane"}, "mount": "nowhere"}]})",
              "no mount called 'nowhere'");
  ExpectError(R"({"tools": [{"name": "t", "preset": "planar-six", "markers": []}]})",
              "exactly one of 'preset', 'markers' or 'stickers'");
  ExpectError(R"({"tools": [{"name": "t", "stickers": {"azimuth_elevation_rad": [[0, 0.5]]}}]})",
              "stickers need a patient");
  ExpectError(R"({"objects": [{"name": "a", "shape": {"kind": "box"}},
                              {"name": "a", "shape": {"kind": "box"}}]})",
              "the name 'a' is used twice");
  ExpectError(R"({"objects": [{"name": "a", "shape": {"kind": "plane"},
                   "pose": {"matrix": [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}}]})",
              "$.objects[0].pose.matrix: ");
  ExpectError(R"({"frames": 3,)", "invalid JSON");
  ExpectError(R"({"seed": 1e999})", "invalid JSON");
  ExpectError(R"({"patient": {"phantom": {"segments": 5000}}})", "must be <= 1024");
  ExpectError(R"({"patient": {"phantom": {"segments": 17}}})", "$.patient.phantom: ");
}

TEST(ParseScenarioJson, UnreadableCtHeadsAndUnknownHeadsAreRefused) {
  ExpectError(R"({"patient": {"head": "ct:/data/head.nrrd"}})", "/data/head.nrrd");
  ExpectError(R"({"patient": {"head": "skull"}})", "expected \"phantom\"");
}

TEST(ParseScenarioJson, MeshHeadsAndMeshShapesResolveRelativeToTheFile) {
  const testing::TempDir dir("scenario_json_mesh");
  // A closed sphere in image coordinates as the "head".
  WriteMesh(dir.path() / "head.ply", sim::SphereMesh(80.0, 48));
  const sim::Scenario s = ParseScenarioJson(
      R"({"patient": {"head": "mesh:head.ply"},
          "objects": [{"name": "ball", "shape": {"kind": "mesh", "path": "head.ply"}}]})",
      dir.path() / "scenario.json");
  ASSERT_TRUE(s.patient.has_value());
  EXPECT_THAT(s.patient->head_source, HasSubstr("head.ply"));
  EXPECT_NEAR(s.patient->anatomy.semi_axes_mm.x(), 80.0, 1e-3);
  EXPECT_EQ(s.patient->plan.size(), 9u);
  EXPECT_FALSE(s.scene.objects[1].mesh.vertex_normals.empty());
  EXPECT_THROW(ParseScenarioJson(R"({"patient": {"head": "mesh:missing.ply"}})",
                                 dir.path() / "scenario.json"),
               IoError);
}

TEST(LoadScenario, BuiltinNameOrFile) {
  EXPECT_EQ(LoadScenario("depth-accuracy").name, "depth-accuracy");
  EXPECT_THAT([] { LoadScenario("no-such-scenario"); },
              ThrowsMessage<IoError>(HasSubstr("marker-stage")));
}

}  // namespace
}  // namespace tofnav
