// SPDX-License-Identifier: BSD-3-Clause
// tofnav simulate end to end: every built-in, a few frames, read back with the foundation
// readers and checked against truth.json; same seed -> same bytes.
#include "tofnav/scenario/simulate.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "matchers.hpp"
#include "simulate_test_helpers.hpp"
#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_test_helpers.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/scenario/truth_json.hpp"
#include "tofnav/sim/scenario_builtins.hpp"
#include "tofnav/sim/simulator.hpp"
#include "tofnav/volume/volume_io.hpp"

namespace tofnav {
namespace {

using Json = nlohmann::json;
using testing::ReadJson;
using testing::SharedCamera;

constexpr int kFrames = 2;
constexpr double kPoseTolMm = 1e-3;  // world_from_rig is stored as float32 metres
constexpr double kPoseTolRad = 1e-6;
constexpr double kExactTol = 1e-9;        // truth matrices composed in double
constexpr std::uint16_t kRetroAb = 1000;  // marker centres: far above skin or boards (< 400)
// Retro-reflection is checked where it is strong: entrance angles well below the 55 deg cut-off.
constexpr double kBrightEntranceRad = 0.8;
constexpr int kWindowPx = 100;  // rendered window around the first tool

// A built-in made cheap for unoptimised builds: one ray per pixel in a small window around the
// marker that faces the camera best in the first frame (or the image centre), a coarse CT.
sim::Scenario SmallBuiltin(const std::string& name) {
  sim::Scenario s = sim::BuiltinScenario(name);
  s.render.supersampling = 1;
  Eigen::Vector2d centre(256.0, 256.0);
  double best_facing = 0.5;
  const Rigid3d ahat_from_world = sim::ScenarioCameraPose(s, 0).Inverse();
  const std::vector<Rigid3d> world_from_mounts = sim::ScenarioMountPoses(s, 0);
  for (std::size_t t = 0; t < s.scene.tools.size(); ++t) {
    const int mount = s.tool_mounts[t];
    const Rigid3d ahat_from_tool =
        ahat_from_world *
        (mount < 0 ? Rigid3d() : world_from_mounts[static_cast<std::size_t>(mount)]) *
        s.scene.tools[t].scene_from_tool;
    for (const sim::Marker& m : s.scene.tools[t].markers) {
      const Eigen::Vector3d c = ahat_from_tool * m.centre_in_tool;
      const double facing = -(ahat_from_tool.rotation * m.normal_in_tool).dot(c.normalized());
      const std::optional<Eigen::Vector2d> uv = SharedCamera()->camera.Project(c);
      if (uv && facing > best_facing) {
        best_facing = facing;
        centre = *uv;
      }
    }
  }
  const auto corner = [](double c) {
    return std::clamp(static_cast<int>(std::lround(c)) - kWindowPx / 2, 0, kAhatWidth - kWindowPx);
  };
  s.render.window = {corner(centre.x()), corner(centre.y()), kWindowPx, kWindowPx};
  if (s.patient) {
    s.patient->ct.spacing_mm = 8.0;
    s.patient->ct.subsamples = 1;
  }
  return s;
}

SimulateOptions SmallRun(std::uint64_t seed = 1) {
  SimulateOptions options;
  options.frames = kFrames;
  options.seed = seed;
  options.truth_depth = true;
  options.camera = SharedCamera();
  return options;
}

Rigid3d RigidFromJson(const Json& rows) {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = rows.at(r).at(c).get<double>();
  }
  return Rigid3d::FromMatrix(m, 1e-9);
}

Eigen::Vector3d VectorFromJson(const Json& v) {
  return {v.at(0).get<double>(), v.at(1).get<double>(), v.at(2).get<double>()};
}

// Checks every output of one run against the readers; returns the number of markers checked for
// brightness.
int CheckOutputs(const sim::Scenario& s, const std::filesystem::path& dir) {
  const std::unique_ptr<Hl2ssRecording> recording = OpenHl2ssRecording(dir / "rm_depth_ahat.bin");
  EXPECT_EQ(recording->frame_count(), static_cast<std::size_t>(kFrames));
  EXPECT_EQ(recording->config().mode, 1);
  const Json truth = ReadJson(dir / "truth.json");
  EXPECT_EQ(truth.at("format"), "tofnav-simulation-truth");
  EXPECT_EQ(truth.at("frame_count"), kFrames);
  const Json& frames = truth.at("frames");
  EXPECT_EQ(frames.size(), static_cast<std::size_t>(kFrames));

  // The calibration on disk is the one the frames were rendered with.
  const AhatCalibration calibration = ReadHl2ssCalibration(dir / "calibration");
  EXPECT_EQ(calibration.uv2xy, SharedCamera()->calibration.uv2xy);
  EXPECT_EQ(calibration.sample_offset_px, SharedCamera()->calibration.sample_offset_px);
  EXPECT_THAT(calibration.rig_from_ahat,
              RigidNear(RigidFromJson(truth.at("rig_from_ahat")), 1e-6, 1e-4));  // f32 file

  const std::vector<std::uint8_t> range_bytes = ReadFileBytes(dir / "truth_range_f32.bin");
  EXPECT_EQ(range_bytes.size(), static_cast<std::size_t>(kFrames) * kAhatPixels * sizeof(float));
  const auto truth_range = [&](std::size_t frame, int u, int v) {
    float value = 0.0f;
    std::memcpy(
        &value,
        range_bytes.data() + (frame * kAhatPixels + static_cast<std::size_t>(v) * kAhatWidth +
                              static_cast<std::size_t>(u)) *
                                 sizeof(float),
        sizeof(float));
    return static_cast<double>(value);
  };

  int bright = 0;
  for (std::size_t i = 0; i < frames.size() && i < recording->frame_count(); ++i) {
    const Json& f = frames[i];
    const AhatFrame frame = recording->ReadFrame(i);
    EXPECT_EQ(f.at("timestamp").get<std::uint64_t>(), frame.host_ticks);
    EXPECT_EQ(f.at("index").get<std::size_t>(), i);
    EXPECT_THAT(*frame.world_from_rig,
                RigidNear(RigidFromJson(f.at("world_from_rig")), kPoseTolRad, kPoseTolMm));
    for (const sim::Tool& tool : s.scene.tools) {
      const Rigid3d ahat_from_tool = RigidFromJson(f.at("ahat_from_" + tool.name));
      for (const Json& marker : f.at("visible_markers").at(tool.name)) {
        const Eigen::Vector3d centre = VectorFromJson(marker.at("centre_in_ahat"));
        const auto index = marker.at("marker").get<std::size_t>();
        EXPECT_NEAR((ahat_from_tool * tool.markers[index].centre_in_tool - centre).norm(), 0.0,
                    kExactTol);
        const Eigen::Vector2d uv(marker.at("pixel_uv").at(0).get<double>(),
                                 marker.at("pixel_uv").at(1).get<double>());
        EXPECT_NEAR((*SharedCamera()->camera.Project(centre) - uv).norm(), 0.0, 1e-9);
        const int u = static_cast<int>(std::lround(uv.x())),
                  v = static_cast<int>(std::lround(uv.y()));
        // Markers cut by the window edge may have their centre outside it.
        const sim::PixelRect& w = s.render.window;
        if (u < w.u0 + 2 || v < w.v0 + 2 || u > w.u0 + w.width - 3 || v > w.v0 + w.height - 3) {
          continue;
        }
        // The first surface along the centre pixel's ray is the marker (within its size).
        EXPECT_NEAR(truth_range(i, u, v), centre.norm(), tool.markers[index].diameter_mm);
        if (marker.at("entrance_angle_rad").get<double>() > kBrightEntranceRad) continue;
        EXPECT_GT(frame.ab(u, v), kRetroAb) << tool.name << " marker " << index;
        ++bright;
      }
    }
  }
  return bright;
}

void CheckPatientOutputs(const sim::Scenario& s, const std::filesystem::path& dir) {
  const sim::Patient& patient = *s.patient;
  const CtVolume ct = ReadVolume(dir / "ct.nrrd");
  const Eigen::Vector3d brain = ct.PointToIjk(patient.anatomy.centre_in_image);
  constexpr double kNoiseTolHu = 80.0;  // 12 HU noise, plus partial volume at 6 mm
  EXPECT_NEAR(
      ct.at(static_cast<int>(std::lround(brain.x())), static_cast<int>(std::lround(brain.y())),
            static_cast<int>(std::lround(brain.z()))),
      patient.ct.brain_hu, kNoiseTolHu);
  EXPECT_NEAR(ct.at(0, 0, 0), patient.ct.air_hu, kNoiseTolHu);

  const TriangleMesh skin = ReadMesh(dir / "skin_truth.ply");
  const TriangleMesh& truth_skin = s.scene.objects[static_cast<std::size_t>(patient.object)].mesh;
  ASSERT_EQ(skin.vertices.size(), truth_skin.vertices.size());
  EXPECT_NEAR((skin.vertices[17] - truth_skin.vertices[17]).norm(), 0.0, 1e-4);  // float32 PLY

  const Json plan = ReadJson(dir / "plan.mrk.json");
  ASSERT_EQ(plan.at("markups").size(), patient.plan.size());
  for (std::size_t t = 0; t < patient.plan.size(); ++t) {
    const Json& line = plan.at("markups")[t];
    EXPECT_EQ(line.at("type"), "Line");
    EXPECT_EQ(line.at("coordinateSystem"), "LPS");
    EXPECT_EQ(line.at("controlPoints")[0].at("label"), "entry");
    EXPECT_NEAR((VectorFromJson(line.at("controlPoints")[0].at("position")) -
                 patient.plan[t].entry_in_image)
                    .norm(),
                0.0, kExactTol);
    EXPECT_NEAR((VectorFromJson(line.at("controlPoints")[1].at("position")) -
                 patient.plan[t].target_in_image)
                    .norm(),
                0.0, kExactTol);
  }

  // <tool>_from_image closes the chain ahat <- tool <- image for tools rigid with the patient.
  const Json truth = ReadJson(dir / "truth.json");
  const std::string head = s.scene.objects[static_cast<std::size_t>(patient.object)].name;
  for (const int t : s.ToolsRigidWithPatient()) {
    const std::string& name = s.scene.tools[static_cast<std::size_t>(t)].name;
    const Rigid3d tool_from_image = RigidFromJson(truth.at(name + "_from_image"));
    for (const Json& f : truth.at("frames")) {
      EXPECT_THAT(
          RigidFromJson(f.at("ahat_from_" + name)) * tool_from_image,
          RigidNear(RigidFromJson(f.at("ahat_from_objects").at(head)), kExactTol, kExactTol));
    }
  }
  // tools/headframe.json joins the reference tools in the first one's frame: each part's markers
  // land where the part's own pose puts them, and headframe_from_image is the first's.
  const std::vector<int> parts = HeadframeTools(s);
  if (parts.empty()) return;
  const ToolGeometry headframe = ReadToolJson(dir / "tools" / "headframe.json");
  const std::string first = s.scene.tools[static_cast<std::size_t>(parts.front())].name;
  EXPECT_THAT(RigidFromJson(truth.at("headframe_from_image")),
              RigidNear(RigidFromJson(truth.at(first + "_from_image")), kExactTol, kExactTol));
  const Json& f = truth.at("frames").at(0);
  std::size_t k = 0;
  for (const int p : parts) {
    const sim::Tool& part = s.scene.tools[static_cast<std::size_t>(p)];
    for (const sim::Marker& m : part.markers) {
      ASSERT_LT(k, headframe.markers_in_tool.size());
      const Eigen::Vector3d joined =
          RigidFromJson(f.at("ahat_from_" + first)) * headframe.markers_in_tool[k++];
      EXPECT_NEAR(
          (joined - RigidFromJson(f.at("ahat_from_" + part.name)) * m.centre_in_tool).norm(), 0.0,
          kPoseTolMm);
    }
  }
  EXPECT_EQ(k, headframe.markers_in_tool.size());
}

class SimulateBuiltin : public ::testing::TestWithParam<std::string> {};

TEST_P(SimulateBuiltin, OutputsPassTheReadersAndMatchTheTruth) {
  const testing::TempDir dir("simulate_" + GetParam());
  const sim::Scenario s = SmallBuiltin(GetParam());
  const SimulateResult result = RunSimulation(s, dir.path(), SmallRun());
  EXPECT_EQ(result.frames, kFrames);
  const int bright = CheckOutputs(s, dir.path());
  if (!s.scene.tools.empty()) {
    EXPECT_GT(bright, 0);  // the marker checks ran
  }
  EXPECT_EQ(std::filesystem::exists(dir.path() / "ct.nrrd"), s.patient.has_value());
  if (s.patient) CheckPatientOutputs(s, dir.path());
}

INSTANTIATE_TEST_SUITE_P(AllBuiltins, SimulateBuiltin,
                         ::testing::ValuesIn(sim::BuiltinScenarioNames()),
                         [](const auto& param_info) {
                           std::string name = param_info.param;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

}  // namespace
}  // namespace tofnav
