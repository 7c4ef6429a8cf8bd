// SPDX-License-Identifier: BSD-3-Clause
// Scenario sanity: sunk spheres and buried discs are found with their depth; clear markers pass.
#include "tofnav/sim/scenario_sanity.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tofnav/core/require.hpp"
#include "tofnav/sim/occluders.hpp"
#include "tofnav/sim/patient.hpp"
#include "tofnav/sim/scenario_builtins.hpp"
#include "tofnav/sim/shapes.hpp"
#include "tofnav/sim/tool_presets.hpp"

namespace tofnav::sim {
namespace {

Rigid3d At(const Eigen::Vector3d& t) { return {Eigen::Quaterniond::Identity(), t}; }

const PatientHead& Phantom() {
  static const PatientHead head = PhantomHead();
  return head;
}

// The phantom head with image = world (its crown, a vertex of the mesh, at z = 110 mm) and one
// tool of `markers` in the world.
Scenario HeadWith(std::vector<Marker> markers) {
  Scenario s;
  s.name = "sanity";
  s.frames = 2;
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial());
  AddPatient(s, Phantom(), s.scene.AddMaterial(SkinMaterial()), -1, Rigid3d::Identity());
  for (Marker& m : markers) m.material = retro;
  s.AddTool({"reference_left", std::move(markers), Rigid3d::Identity()}, -1);
  return s;
}

TEST(ScenarioSanity, ASphereSunkIntoTheScalpIsRefusedWithItsDepth) {
  const Eigen::Vector3d crown(0.0, 0.0, 110.0);
  ASSERT_NEAR(Phantom().Probe().RequireHit(Eigen::Vector3d::UnitZ(), "").point.z(), 110.0, 1e-9);
  // Centre 2.65 mm over the crown: the 11.5 mm sphere reaches 5.75 - 2.65 = 3.1 mm into the skin.
  const Scenario s = HeadWith({SphereMarker({30.0, 0.0, 200.0}, 11.5, 0),
                               SphereMarker({-30.0, 0.0, 200.0}, 11.5, 0),
                               SphereMarker(crown + Eigen::Vector3d(0.0, 0.0, 2.65), 11.5, 0)});
  const std::vector<MarkerIntersection> found = FindMarkerIntersections(s);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].marker, 2);
  EXPECT_NEAR(found[0].depth_mm, 3.1, 1e-3);  // the straight-down probe meets the crown vertex
  try {
    RequireMarkersClear(s);
    FAIL() << "the sunk sphere was accepted";
  } catch (const PreconditionError& e) {
    EXPECT_STREQ(e.what(),
                 "scenario: tool 'reference_left' marker 2 (sphere, 11.5 mm) intersects the head "
                 "surface by 3.1 mm");
  }
}

TEST(ScenarioSanity, ASphereWhoseCentreIsInsideTheHeadReachesBeyondItsRadius) {
  // Centre 4 mm under the crown: the sphere is in the skin by 5.75 + 4 mm.
  const Scenario s = HeadWith({SphereMarker({0.0, 0.0, 106.0}, 11.5, 0)});
  const std::vector<MarkerIntersection> found = FindMarkerIntersections(s);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NEAR(found[0].depth_mm, 9.75, 0.05);  // the crown's curvature: < 0.05 mm off 4 mm
}

TEST(ScenarioSanity, ADiscUnderAPlateIsRefusedAndOneOnItAccepted) {
  Scenario s;
  s.name = "plate";
  s.frames = 1;
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial());
  s.AddObject("plate", PlaneMesh(80.0, 60.0), s.scene.AddMaterial(PlaMaterial()), -1,
              At({0.0, 0.0, 400.0}));
  Tool tool = ToolPreset("reference-a", "reference_left", retro);  // discs 0.1 mm over z = 0
  tool.scene_from_tool = At({0.0, 0.0, 400.0});
  s.AddTool(tool, -1);
  EXPECT_TRUE(FindMarkerIntersections(s).empty());
  s.scene.tools[0].markers[1] =
      DiscMarkerOnSurface({26.0, -22.0, 0.0}, Eigen::Vector3d::UnitZ(), 10.0, retro, -1.0);
  const std::vector<MarkerIntersection> found = FindMarkerIntersections(s);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].marker, 1);
  EXPECT_NEAR(found[0].depth_mm, 1.0, 1e-3);
  EXPECT_EQ(DescribeMarkerIntersection(s, found[0]),
            "scenario: tool 'reference_left' marker 1 (disc, 10 mm) intersects the plate surface "
            "by 1.0 mm");
}

TEST(ScenarioSanity, SpheresOnPostsOverTheirPlateAreClear) {
  Scenario s;
  s.name = "posts";
  s.frames = 1;
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial());
  s.AddObject("plate", PlaneMesh(120.0, 120.0), s.scene.AddMaterial(PlaMaterial()), -1,
              At({20.0, 35.0, 0.0}));
  s.AddTool(ToolPreset("spheres-four", "tool", retro), -1);  // 11.5 mm on 8 mm posts: 2.25 mm gap
  EXPECT_TRUE(FindMarkerIntersections(s).empty());
}

TEST(ScenarioSanity, AHandThroughAMarkerAtAKeyframeIsFoundAtThatSlot) {
  Scenario s = HeadWith({SphereMarker({0.0, 0.0, 200.0}, 11.5, 0)});
  s.frames = 100;
  const Rigid3d parked = At({0.0, 3000.0, 0.0});
  Pass pass;
  pass.enter_slot = 40;
  pass.hover = At({-100.0, 0.0, 200.0});  // the palm's axis through the sphere's centre
  AddHand(s, "hand", HandOptions{}, 1, PassesMotion(parked, {pass}));  // material 1: skin
  const std::vector<MarkerIntersection> found = FindMarkerIntersections(s);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].slot, 40);  // no approach shift: it enters at the hover pose
  EXPECT_EQ(s.scene.objects[static_cast<std::size_t>(found[0].object)].name, "hand");
  // Centre on the palm's axis: r + 22.5 mm, less the 32 facets' 0.11 mm chord sag.
  EXPECT_NEAR(found[0].depth_mm, 5.75 + 22.5, 0.15);
  EXPECT_NE(DescribeMarkerIntersection(s, found[0]).find(", at slot 40"), std::string::npos);
}

// A 90 mm ball with a 2.5 mm wart 4 mm beside where a 10 mm sticker goes (straight anterior):
// flat on the ball, a rigid sticker's rim would sink 2.5 mm into the wart.
Scenario WartScenario(bool conform) {
  TriangleMesh skin = SphereMesh(90.0, 192);
  const TriangleMesh wart = SphereMesh(2.5, 16);
  const auto offset = static_cast<int>(skin.vertices.size());
  for (const Eigen::Vector3d& v : wart.vertices)
    skin.vertices.push_back(v + Eigen::Vector3d(4, -90, 0));
  skin.vertex_normals.insert(skin.vertex_normals.end(), wart.vertex_normals.begin(),
                             wart.vertex_normals.end());
  for (const Eigen::Vector3i& t : wart.triangles)
    skin.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
  Scenario s;
  s.name = "wart";
  s.frames = 1;
  PatientHead head = MeshHead(skin, "mesh:wart");
  head.anatomy.centre_in_image = Eigen::Vector3d::Zero();  // the ball's centre
  AddPatient(s, head, s.scene.AddMaterial(SkinMaterial()), -1, Rigid3d::Identity());
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial());
  s.AddTool(SkinStickers("sticker", head, {HeadDirection(0.0, 0.0)}, 10.0, retro,
                         conform ? s.patient->object : -1),
            -1);
  return s;
}

TEST(ScenarioSanity, RigidStickersOnARoughSkinAreLiftedClearOfIt) {
  const Scenario s = WartScenario(false);
  const Marker& sticker = s.scene.tools[0].markers[0];
  EXPECT_EQ(sticker.conforms_to_object, -1);
  // Lifted over the wart (2.5 mm high; the probes at half and full radius meet it 1 mm off its top,
  // 2.29 mm high), against 0.24 mm on the bare ball.
  EXPECT_GT(sticker.centre_in_tool.norm() - 90.0, 2.2);
  EXPECT_TRUE(FindMarkerIntersections(s).empty());
}

TEST(ScenarioSanity, TapeStickersLieOnTheMeanPlaneOfARoughSkin) {
  const Scenario s = WartScenario(true);
  const Marker& sticker = s.scene.tools[0].markers[0];
  EXPECT_EQ(sticker.conforms_to_object, s.patient->object);
  // 0.1 mm of tape over the mean plane of the 33 skin points probed under it, which the wart
  // (a few of them, up to 2.5 mm high) lifts and tilts: far below the rigid disc's 2.2 mm.
  EXPECT_GT(sticker.centre_in_tool.norm() - 90.0, 0.1);
  EXPECT_LT(sticker.centre_in_tool.norm() - 90.0, 0.5);
  EXPECT_LT(std::acos(-sticker.normal_in_tool.y()), 0.2);  // anterior (-y), 9 deg off by the wart
  EXPECT_TRUE(FindMarkerIntersections(s).empty());         // drawn on the skin: not probed
}

TEST(ScenarioSanity, EveryBuiltInScenarioIsClear) {
  for (const std::string& name : BuiltinScenarioNames()) {
    const Scenario s = BuiltinScenario(name);
    const std::vector<MarkerIntersection> found = FindMarkerIntersections(s, {.tolerance_mm = 0.0});
    const double deepest = found.empty() ? 0.0 : found[0].depth_mm;
    for (const MarkerIntersection& f : found)
      std::printf("  %s\n", DescribeMarkerIntersection(s, f).c_str());
    std::printf("%s: deepest marker intersection %.3f mm\n", name.c_str(), deepest);
    EXPECT_LE(deepest, MarkerClearanceOptions{}.tolerance_mm) << name;
  }
}

}  // namespace
}  // namespace tofnav::sim
