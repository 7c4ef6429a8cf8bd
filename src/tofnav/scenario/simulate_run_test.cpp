// SPDX-License-Identifier: BSD-3-Clause
// tofnav simulate: byte-identical reruns, tofnav info on every output, options.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "simulate_test_helpers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/describe/describe.hpp"
#include "tofnav/io/io_test_helpers.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/scenario/simulate.hpp"
#include "tofnav/sim/patient.hpp"
#include "tofnav/sim/shapes.hpp"

namespace tofnav {
namespace {

using testing::ReadJson;
using testing::SharedCamera;

SimulateOptions SmallRun(std::uint64_t seed = 1) {
  SimulateOptions options;
  options.frames = 2;
  options.seed = seed;
  options.truth_depth = true;
  options.camera = SharedCamera();
  return options;
}

// A small patient scenario: a coarse phantom with two stickers facing a fixed camera.
sim::Scenario TinyPatientScenario() {
  sim::Scenario s;
  s.name = "tiny-patient";
  const int retro = s.scene.AddMaterial(sim::RetroReflectiveMaterial());
  sim::HeadPhantomOptions coarse;
  coarse.segments = 48;
  const sim::PatientHead head = sim::PhantomHead(coarse);
  sim::AddPatient(s, head, s.scene.AddMaterial(sim::NylonMaterial()), -1, Rigid3d());
  s.AddTool(sim::SkinStickers("stickers", head,
                              {sim::HeadDirection(0.1, 0.4), sim::HeadDirection(-0.2, 0.5)}, 10.0,
                              retro, s.patient->object),
            -1);
  // LPS: the face looks along -y; the camera stands 400 mm in front of it.
  s.camera.motion = sim::StaticMotion(
      sim::LookAt({0.0, -400.0, 30.0}, {0.0, 0.0, 30.0}, Eigen::Vector3d::UnitZ()));
  s.render.supersampling = 1;
  s.render.window = {224, 224, 64, 64};
  s.patient->ct.spacing_mm = 8.0;
  s.patient->ct.subsamples = 1;
  return s;
}

TEST(RunSimulation, SameSeedSameBytesOtherSeedOtherData) {
  const testing::TempDir a("simulate_a"), b("simulate_b"), c("simulate_c");
  const sim::Scenario s = TinyPatientScenario();
  SimulateOptions one = SmallRun(5);
  SimulateOptions other = one;
  other.seed = 6;
  RunSimulation(s, a.path(), one);
  RunSimulation(s, b.path(), one);
  RunSimulation(s, c.path(), other);
  for (const char* file :
       {"rm_depth_ahat.bin", "truth.json", "truth_range_f32.bin", "ct.nrrd", "skin_truth.ply",
        "plan.mrk.json", "calibration/rm_depth_ahat/uv2xy.bin"}) {
    EXPECT_EQ(ReadFileBytes(a.path() / file), ReadFileBytes(b.path() / file)) << file;
  }
  for (const char* file : {"rm_depth_ahat.bin", "truth.json", "ct.nrrd"}) {
    EXPECT_NE(ReadFileBytes(a.path() / file), ReadFileBytes(c.path() / file)) << file;
  }
}

TEST(RunSimulation, TofnavInfoDescribesEveryOutput) {
  const testing::TempDir dir("simulate_info");
  RunSimulation(TinyPatientScenario(), dir.path(), SmallRun());
  EXPECT_THAT(DescribeAsJson(dir.path() / "rm_depth_ahat.bin"),
              ::testing::HasSubstr("\"recording\""));
  EXPECT_THAT(DescribeAsJson(dir.path() / "calibration"), ::testing::HasSubstr("\"calibration\""));
  EXPECT_THAT(DescribeAsJson(dir.path() / "ct.nrrd"), ::testing::HasSubstr("\"volume\""));
  EXPECT_THAT(DescribeAsJson(dir.path() / "skin_truth.ply"), ::testing::HasSubstr("\"mesh\""));
  const std::string truth = DescribeAsJson(dir.path() / "truth.json");
  EXPECT_THAT(truth, ::testing::HasSubstr("\"simulation truth\""));
  EXPECT_THAT(truth, ::testing::HasSubstr("\"frames\": 2"));
  const std::string plan = DescribeAsJson(dir.path() / "plan.mrk.json");
  EXPECT_THAT(plan, ::testing::HasSubstr("\"Line\": 9"));
}

TEST(RunSimulation, WritesEveryObjectMeshNamedInTruth) {
  const testing::TempDir dir("simulate_meshes");
  sim::Scenario s = TinyPatientScenario();
  s.AddObject("ball", sim::SphereMesh(20.0, 16), s.scene.objects.front().material, -1,
              Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())),
                      {150.0, -100.0, 0.0}));
  SimulateOptions options = SmallRun();
  options.frames = 1;
  RunSimulation(s, dir.path(), options);
  const testing::Json truth = ReadJson(dir.path() / "truth.json");
  EXPECT_EQ(truth.at("files").at("skin"), "skin_truth.ply");
  ASSERT_EQ(s.scene.objects.size(), 2u);
  for (const sim::SceneObject& o : s.scene.objects) {
    SCOPED_TRACE(o.name);
    const std::string name = "meshes/" + o.name + ".ply";
    ASSERT_EQ(truth.at("files").at("mesh:" + o.name), name);
    // The object's own frame, exactly at the PLY's float precision (positions and triangles).
    const TriangleMesh mesh = ReadMesh(dir.path() / name);
    EXPECT_EQ(truth.at("objects").at(o.name).at("vertices"), mesh.vertices.size());
    EXPECT_EQ(truth.at("objects").at(o.name).at("triangles"), mesh.triangles.size());
    ASSERT_EQ(mesh.vertices.size(), o.mesh.vertices.size());
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
      ASSERT_EQ(mesh.vertices[i], o.mesh.vertices[i].cast<float>().cast<double>()) << i;
    }
    EXPECT_EQ(mesh.triangles, o.mesh.triangles);
  }
}

TEST(RunSimulation, ZdepthProfileAndOptionChecks) {
  const testing::TempDir dir("simulate_zdepth");
  const sim::Scenario s = TinyPatientScenario();
  SimulateOptions options = SmallRun();
  options.frames = 1;
  options.truth_depth = false;
  options.profile = {Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kRaw};
  RunSimulation(s, dir.path(), options);
  EXPECT_EQ(OpenHl2ssRecording(dir.path() / "rm_depth_ahat.bin")->config().profile_z,
            Hl2ssDepthProfile::kZdepth);
  EXPECT_EQ(ReadJson(dir.path() / "truth.json").at("profile"), "zdepth");
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "truth_range_f32.bin"));
  options.frames = 0;
  EXPECT_THROW(RunSimulation(s, dir.path(), options), PreconditionError);
}

}  // namespace
}  // namespace tofnav
