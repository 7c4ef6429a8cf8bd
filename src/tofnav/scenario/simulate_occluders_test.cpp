// SPDX-License-Identifier: BSD-3-Clause
// Occluders through the scenario schema and `simulate`: hands, drapes, keyframes, an instrument
// tracked from the written recording and tool file, occlusion truth, the sunk-marker refusal.
#include <gtest/gtest.h>

#include <numbers>
#include <string>

#include "simulate_test_helpers.hpp"
#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/io_test_helpers.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/open_recording.hpp"
#include "tofnav/scenario/scenario_json.hpp"
#include "tofnav/scenario/simulate.hpp"
#include "tofnav/sim/occluders.hpp"
#include "tofnav/tracking/tool_pose.hpp"

namespace tofnav {
namespace {

// A spheres-four instrument on a rod swinging 380-420 mm in front of a static headset, a wall
// behind, and a hand that parks out of view but for slot 3, when it hovers 250 mm from the camera
// across the instrument's line of sight. f_rf and the 1 mm cyclic wiggle are off (retro_curve none,
// wiggle_amplitude_mm 0): raw marker ranges then carry no systematic error to correct.
constexpr const char* kInstrumentScenario = R"({
  "name": "instrument-pass", "frames": 6,
  "materials": [{"name": "tape", "preset": "retro_reflective", "retro_curve": "none"}],
  "mounts": [
    {"name": "probe_motion", "motion": {"kind": "keyframes", "keyframes": [
      {"slot": 0, "pose": {"look_at": {"eye_mm": [-30, -30, 380], "target_mm": [-30, -30, 0]}}},
      {"slot": 5, "pose": {"look_at": {"eye_mm": [0, -20, 420], "target_mm": [80, 20, 0]}}}]}},
    {"name": "hand_motion", "motion": {"kind": "keyframes", "keyframes": [
      {"slot": 2, "pose": {"translation_mm": [0, 3000, 0]}},
      {"slot": 3, "pose": {"translation_mm": [-60, 0, 250]}},
      {"slot": 4, "pose": {"translation_mm": [0, 3000, 0]}}]}}],
  "objects": [
    {"name": "wall", "shape": {"kind": "plane", "width_mm": 3000, "height_mm": 3000},
     "pose": {"translation_mm": [0, 0, 900]}},
    {"name": "hand", "shape": {"kind": "hand"}, "mount": "hand_motion"},
    {"name": "drape", "shape": {"kind": "drape", "seed": 7, "cell_mm": 20},
     "pose": {"translation_mm": [0, 600, 600]}}],
  "tools": [{"name": "probe", "preset": "spheres-four", "material": "tape",
             "mount": "probe_motion", "instrument": {"rod_diameter_mm": 4, "rod_length_mm": 200}}],
  "render": {"sensor": {"wiggle_amplitude_mm": 0}}
})";

sim::Scenario InstrumentScenario() {
  sim::Scenario s = ParseScenarioJson(kInstrumentScenario, "instrument.json");
  s.render.window = {156, 156, 200, 200};  // around the optical axis: the instrument's region
  return s;
}

TEST(ScenarioJsonOccluders, HandDrapeInstrumentAndKeyframesAreRead) {
  const sim::Scenario s = InstrumentScenario();
  const auto object = [&](const char* name) -> const sim::SceneObject& {
    return s.scene.objects.at(static_cast<std::size_t>(s.FindObject(name)));
  };
  const auto material = [&](const char* name) {
    return s.scene.materials[static_cast<std::size_t>(object(name).material)].name;
  };
  EXPECT_EQ(object("hand").mesh.vertices, sim::HandMesh().vertices);
  EXPECT_EQ(material("hand"), "skin");  // the default material of a hand
  sim::DrapeOptions drape;
  drape.seed = 7;
  drape.cell_mm = 20.0;
  EXPECT_EQ(object("drape").mesh.vertices, sim::DrapeMesh(drape).vertices);
  EXPECT_EQ(material("drape"), "drape");
  EXPECT_EQ(object("probe_rod").mesh.vertices, sim::InstrumentRodMesh().vertices);
  const sim::Motion& probe =
      s.mounts.at(static_cast<std::size_t>(s.FindMount("probe_motion"))).motion;
  ASSERT_EQ(probe.kind, sim::MotionKind::kKeyframes);
  EXPECT_EQ(probe.keyframes.size(), 2u);
  EXPECT_EQ(probe.keyframes[1].slot, 5);
}

TEST(ScenarioJsonOccluders, BadKeyframesAndInstrumentsAreNamed) {
  const auto error = [](const std::string& text) {
    try {
      ParseScenarioJson(text, "bad.json");
    } catch (const IoError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(error(R"({"mounts": [{"name": "m", "motion": {"kind": "keyframes", "keyframes": [
              {"slot": 4, "pose": {}}, {"slot": 4, "pose": {}}]}}]})")
                .find("strictly increasing"),
            std::string::npos);
  EXPECT_NE(error(R"({"mounts": [{"name": "m", "motion": {"kind": "keyframes",
              "keyframes": [{"pose": {}}]}}]})")
                .find("$.mounts[0].motion.keyframes[0].slot: required key is missing"),
            std::string::npos);
  EXPECT_NE(error(R"({"tools": [{"name": "t", "markers": [], "instrument": {}}]})")
                .find("$.tools[0].instrument: an instrument needs a preset"),
            std::string::npos);
}

TEST(RunSimulationOccluders, TheInstrumentIsTrackedAndTheHandRecordedAsItsOccluder) {
  // Tracking from the recording against truth.json, frames without occlusion. Raw spheres at
  // 380-420 mm: about 0.2 mm of range noise per marker over 30-45 mm lever arms (0.05-0.27 mm,
  // 0.07-0.39 deg seen in single frames); 0.5 mm and 0.75 deg
  // bound that with margin, far below a wrong match (the markers are 44-81 mm apart).
  constexpr double kMaxPositionErrorMm = 0.5, kMaxRotationErrorDeg = 0.75;
  const sim::Scenario s = InstrumentScenario();
  SimulateOptions options;
  options.camera = testing::SharedCamera();
  const testing::TempDir dir("simulate_occluders");
  const SimulateResult result = RunSimulation(s, dir.path(), options);
  const ToolGeometry tool = ReadToolJson(dir.path() / "tools" / "probe.json");
  EXPECT_EQ(tool.marker_type, MarkerType::kSphere);
  const testing::Json truth = testing::ReadJson(dir.path() / "truth.json");
  const std::unique_ptr<AhatRecording> recording =
      OpenAhatRecording(dir.path() / "rm_depth_ahat.bin");
  const AhatCamera camera(ReadHl2ssCalibration(dir.path() / "calibration"));
  ASSERT_EQ(recording->frame_count(), 6u);
  // The spheres' entrance-angle term is taken off as tracking does (docs/tracking.md 4).
  ToolPoseOptions pose_options;
  for (const sim::Material& m : s.scene.materials) {
    if (m.retro_reflective)
      pose_options.marker_entrance_gain_mm_per_rad = m.retro_angle_gain_mm_per_rad;
  }
  int tracked = 0;
  for (std::size_t i = 0; i < 6; ++i) {
    const testing::Json& frame = truth.at("frames").at(i);
    const bool occluded = frame.at("occluded_markers").contains("probe");
    if (i == 3) {  // the hand hides some of the instrument's markers, and truth says so
      ASSERT_TRUE(occluded);
      EXPECT_EQ(frame.at("occluded_markers").at("probe").at(0).at("by"), "hand");
      continue;
    }
    EXPECT_FALSE(occluded) << i;
    Eigen::Matrix4d m;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) m(r, c) = frame.at("ahat_from_probe").at(r).at(c).get<double>();
    const Rigid3d truth_pose = Rigid3d::FromMatrix(m);
    const std::vector<DetectedMarker> markers =
        LocateMarkers(recording->ReadFrame(i), camera).markers;
    const ToolPoseResult pose =
        EstimateToolPoses(markers, std::span(&tool, 1), {}, pose_options)[0];
    ASSERT_TRUE(pose.ahat_from_tool.has_value()) << i;
    const double position_mm = TranslationDistanceMm(*pose.ahat_from_tool, truth_pose);
    const double rotation_deg =
        RotationDistanceRad(*pose.ahat_from_tool, truth_pose) * 180.0 / std::numbers::pi;
    std::printf("frame %zu: instrument %.3f mm, %.3f deg from truth\n", i, position_mm,
                rotation_deg);
    EXPECT_LE(position_mm, kMaxPositionErrorMm) << i;
    EXPECT_LE(rotation_deg, kMaxRotationErrorDeg) << i;
    ++tracked;
  }
  EXPECT_EQ(tracked, 5);
  EXPECT_EQ(result.fully_visible_frames.at(0), 5);  // all but the hand's frame
  EXPECT_TRUE(result.warnings.empty());
}

TEST(RunSimulationOccluders, AToolNeverFullyVisibleIsWarnedAbout) {
  sim::Scenario s = InstrumentScenario();
  s.frames = 1;
  sim::Motion& hand = s.mounts[static_cast<std::size_t>(s.FindMount("hand_motion"))].motion;
  // The palm's axis 250 mm away across the line of sight to marker 0 (at about (-30, -30, 372)):
  // it hides that marker whole.
  hand = sim::StaticMotion(Rigid3d(Eigen::Quaterniond::Identity(), {-60.0, -20.0, 250.0}));
  SimulateOptions options;
  options.camera = testing::SharedCamera();
  const testing::TempDir dir("simulate_hidden");
  const SimulateResult result = RunSimulation(s, dir.path(), options);
  EXPECT_EQ(result.fully_visible_frames.at(0), 0);
  EXPECT_EQ(result.warnings,
            std::vector<std::string>{"tool 'probe' is never fully visible (all 4 markers) in the 1 "
                                     "rendered frames"});
}

TEST(RunSimulationOccluders, ASunkMarkerIsRefusedBeforeAnythingIsWritten) {
  sim::Scenario s = InstrumentScenario();
  sim::Motion& probe = s.mounts[static_cast<std::size_t>(s.FindMount("probe_motion"))].motion;
  probe = sim::StaticMotion(probe.keyframes[0].pose);  // the same depth at every checked slot
  // Inside the rod, 0.45 mm off its axis (x 15.5, z -3): 1.55 mm from its surface, so the sphere
  // reaches 5.75 + 1.55 mm into it (the rod's 16 facets cut 0.04 mm inside the round).
  s.scene.tools[0].markers[0].centre_in_tool = {15.5, 0.0, -2.55};
  const testing::TempDir dir("simulate_sunk");
  const std::filesystem::path out = dir.path() / "out";
  try {
    RunSimulation(s, out, {});
    FAIL() << "accepted";
  } catch (const PreconditionError& e) {
    EXPECT_EQ(std::string(e.what()),
              "scenario: tool 'probe' marker 0 (sphere, 11.5 mm) intersects the probe_rod "
              "surface by 7.3 mm");
  }
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace tofnav
