// SPDX-License-Identifier: BSD-3-Clause
// ReadTruthSurfaces on a simulated session: the session's own mesh files, not a rebuilt scenario.
#include "tofnav/evaluation/reconstruct_evaluate.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/io_test_helpers.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/scenario/simulate.hpp"
#include "tofnav/scenario/simulate_test_helpers.hpp"
#include "tofnav/sim/patient.hpp"
#include "tofnav/sim/shapes.hpp"

namespace tofnav {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

constexpr double kFloatMm = 1e-4;  // meshes/*.ply store float positions (~1e-5 mm at 200 mm)
constexpr double kSagMm = 0.01;    // a 0.5 mm shell's vertices to the faces of a 96-segment ball
constexpr double kBallRadiusMm = 20.0;
constexpr double kShellMm = 0.5;  // the known error of the offset ball

// A scenario no built-in matches: the coarse phantom (48 segments), stickers as the tool, and a
// ball beside the head, all static. Its name is that of a built-in whose head differs, so the
// old scenario rebuild would refuse it (vertex counts differ).
sim::Scenario ModifiedScenario() {
  sim::Scenario s;
  s.name = "evd-usecase";
  const int retro = s.scene.AddMaterial(sim::RetroReflectiveMaterial());
  const int nylon = s.scene.AddMaterial(sim::NylonMaterial());
  sim::HeadPhantomOptions coarse;
  coarse.segments = 48;
  const sim::PatientHead head = sim::PhantomHead(coarse);
  sim::AddPatient(s, head, nylon, -1, Rigid3d());
  s.AddTool(sim::SkinStickers("stickers", head,
                              {sim::HeadDirection(0.1, 0.4), sim::HeadDirection(-0.2, 0.5)}, 10.0,
                              retro, s.patient->object),
            -1);
  s.AddObject("ball", sim::SphereMesh(kBallRadiusMm), nylon, -1,
              Rigid3d(Eigen::Quaterniond::Identity(), {150.0, -100.0, 0.0}));
  s.camera.motion = sim::StaticMotion(
      sim::LookAt({0.0, -400.0, 30.0}, {0.0, 0.0, 30.0}, Eigen::Vector3d::UnitZ()));
  s.render.supersampling = 1;
  s.render.window = {224, 224, 64, 64};
  s.patient->write_ct = false;
  return s;
}

// Simulates ModifiedScenario() once per test binary into a folder of its own.
class ReadTruthSurfacesTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir("reconstruct_evaluate");
    SimulateOptions options;
    options.frames = 2;
    options.seed = 1;
    options.camera = testing::SharedCamera();
    RunSimulation(ModifiedScenario(), dir_->path(), options);
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static testing::TempDir* dir_;
};
testing::TempDir* ReadTruthSurfacesTest::dir_ = nullptr;

TEST_F(ReadTruthSurfacesTest, UsesTheSessionMeshesAndMeasuresAKnownSurface) {
  const sim::Scenario s = ModifiedScenario();
  const std::vector<TruthSurface> truth = ReadTruthSurfaces(dir_->path(), "stickers");
  ASSERT_EQ(truth.size(), 2u);
  EXPECT_EQ(truth[0].name, "head");
  EXPECT_TRUE(truth[0].patient);
  EXPECT_EQ(truth[1].name, "ball");
  EXPECT_EQ(truth[1].material, "nylon");
  const Rigid3d tool_from_world = s.scene.tools.front().scene_from_tool.Inverse();
  for (std::size_t o = 0; o < truth.size(); ++o) {  // the scenario's meshes, posed analytically
    const sim::SceneObject& object = s.scene.objects[o];
    const TriangleMesh expected =
        Transform(tool_from_world * object.scene_from_object, object.mesh);
    ASSERT_EQ(truth[o].mesh_in_tool.vertices.size(), expected.vertices.size());
    for (std::size_t i = 0; i < expected.vertices.size(); ++i) {
      ASSERT_LT((truth[o].mesh_in_tool.vertices[i] - expected.vertices[i]).norm(), kFloatMm);
    }
  }
  // The true ball itself: zero error; the ball grown by 0.5 mm: 0.5 mm outside.
  const sim::SceneObject& ball = s.scene.objects[1];
  const Rigid3d tool_from_ball = tool_from_world * ball.scene_from_object;
  const ReconstructionEvaluation same =
      EvaluateReconstruction(Transform(tool_from_ball, ball.mesh), truth);
  ASSERT_EQ(same.objects.size(), 1u);
  EXPECT_EQ(same.objects[0].name, "ball");
  EXPECT_LT(same.all.abs_mm.median, kFloatMm);
  const ReconstructionEvaluation grown = EvaluateReconstruction(
      Transform(tool_from_ball, sim::SphereMesh(kBallRadiusMm + kShellMm)), truth);
  EXPECT_NEAR(grown.all.abs_mm.median, kShellMm, kSagMm);
  EXPECT_NEAR(grown.all.mean_signed_mm, kShellMm, kSagMm);
  EXPECT_EQ(grown.outliers, 0u);
}

TEST_F(ReadTruthSurfacesTest, AMissingOrChangedMeshFileIsAnIoErrorNamingIt) {
  const testing::TempDir copy("reconstruct_evaluate_copy");
  std::filesystem::copy(dir_->path(), copy.path(), std::filesystem::copy_options::recursive);
  const std::filesystem::path ball = copy.path() / "meshes" / "ball.ply";
  WriteMesh(ball, sim::SphereMesh(kBallRadiusMm, 8));
  const auto read = [&] { ReadTruthSurfaces(copy.path(), "stickers"); };
  EXPECT_THAT(read, ThrowsMessage<IoError>(AllOf(HasSubstr(ball.string()),
                                                 HasSubstr("expected the mesh of object 'ball'"))));
  std::filesystem::remove(ball);
  EXPECT_THAT(read, ThrowsMessage<IoError>(AllOf(HasSubstr(ball.string()), HasSubstr("missing"))));
}

TEST_F(ReadTruthSurfacesTest, ASessionWithoutMeshFilesStillRebuildsTheScenario) {
  const testing::TempDir copy("reconstruct_evaluate_old");
  std::filesystem::copy(dir_->path(), copy.path(), std::filesystem::copy_options::recursive);
  std::filesystem::remove_all(copy.path() / "meshes");
  const std::filesystem::path truth_path = copy.path() / "truth.json";
  testing::Json truth = testing::ReadJson(truth_path);
  truth["files"].erase("mesh:head");
  truth["files"].erase("mesh:ball");
  std::ofstream(truth_path) << truth.dump();
  // As before mesh files: the built-in evd-usecase's head is not this one.
  EXPECT_THAT([&] { ReadTruthSurfaces(copy.path(), "stickers"); },
              ThrowsMessage<PreconditionError>(HasSubstr("mesh of 'head' does not match")));
  truth["scenario"] = "not-a-builtin";  // no scenario: the skin file alone
  std::ofstream(truth_path) << truth.dump();
  const std::vector<TruthSurface> skin = ReadTruthSurfaces(copy.path(), "stickers");
  ASSERT_EQ(skin.size(), 1u);
  EXPECT_EQ(skin[0].name, "head");
}

}  // namespace
}  // namespace tofnav
