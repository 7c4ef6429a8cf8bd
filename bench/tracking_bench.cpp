// SPDX-License-Identifier: BSD-3-Clause
// Per-frame cost of marker detection, matching and pose of two tools on a full 512 x 512 frame
// (target <= 0.3 ms median on one core).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <numbers>
#include <random>

#include "tofnav/markers/bright_blobs.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"
#include "tofnav/sim/render.hpp"
#include "tofnav/sim/shapes.hpp"
#include "tofnav/tracking/tool_tracker.hpp"

namespace tofnav {
namespace {

ToolGeometry Tool(const std::string& name, Points3d markers) {
  ToolGeometry tool;
  tool.name = name;
  tool.markers_in_tool = std::move(markers);
  return tool;
}

const std::vector<ToolGeometry>& Tools() {
  static const std::vector<ToolGeometry> tools = {
      Tool("Reference", {{-20, -45, 35}, {0, 50, 30}, {60, -55, 15}, {-30, 10, 15}}),
      Tool("Pointer", {{5, -55, 10}, {15, 35, 5}, {-40, 5, 30}, {55, 50, 20}})};
  return tools;
}

struct Fixture {
  AhatCamera camera{MakeSyntheticAhatCalibration()};
  AhatFrame frame;
};

// A whole realistic frame: a skin-like wall at 700 mm, a diffuse board, both tools at 400-500 mm.
const Fixture& Frame() {
  static const Fixture fixture = [] {
    Fixture f;
    sim::Scene scene;
    const int wall = scene.AddMaterial(sim::SkinMaterial());
    const int board = scene.AddMaterial(sim::DiffuseMaterial(0.8));
    const int retro = scene.AddMaterial(sim::RetroReflectiveMaterial());
    const Eigen::Quaterniond flip(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()));
    scene.AddObject("wall", sim::PlaneMesh(3000.0, 3000.0), wall, Rigid3d(flip, {0, 0, 700.0}));
    scene.AddObject("board", sim::PlaneMesh(200.0, 150.0), board, Rigid3d(flip, {0, 150, 450.0}));
    const Rigid3d poses[] = {Rigid3d(flip, {-90.0, -20.0, 420.0}),
                             Rigid3d(flip, {100.0, 10.0, 480.0})};
    for (std::size_t t = 0; t < 2; ++t) {
      sim::Tool tool{Tools()[t].name, {}, poses[t]};
      for (const Eigen::Vector3d& p : Tools()[t].markers_in_tool) {
        tool.markers.push_back(sim::SphereMarker(p, 11.5, retro));
      }
      scene.AddTool(tool);
    }
    std::mt19937_64 rng(1);
    f.frame = sim::RenderAhatFrame(scene, f.camera, Rigid3d::Identity(), {}, rng).frame;
    return f;
  }();
  return fixture;
}

void BM_FindBrightBlobs(benchmark::State& state) {
  const Fixture& f = Frame();
  for (auto _ : state) benchmark::DoNotOptimize(FindBrightBlobs(f.frame.ab, kMarkerAbThreshold));
}
BENCHMARK(BM_FindBrightBlobs)->Unit(benchmark::kMicrosecond);

void BM_LocateMarkers(benchmark::State& state) {
  const Fixture& f = Frame();
  for (auto _ : state) benchmark::DoNotOptimize(LocateMarkers(f.frame, f.camera));
}
BENCHMARK(BM_LocateMarkers)->Unit(benchmark::kMicrosecond);

void BM_EstimateToolPoses(benchmark::State& state) {
  const Fixture& f = Frame();
  const std::vector<DetectedMarker> markers = LocateMarkers(f.frame, f.camera).markers;
  if (markers.size() != 8) state.SkipWithError("expected 8 markers");
  for (auto _ : state) benchmark::DoNotOptimize(EstimateToolPoses(markers, Tools()));
}
BENCHMARK(BM_EstimateToolPoses)->Unit(benchmark::kMicrosecond);

// The acceptance figure: detection + matching + pose of two tools per frame.
void BM_DetectMatchPoseTwoTools(benchmark::State& state) {
  const Fixture& f = Frame();
  for (auto _ : state) {
    const MarkerDetectionResult detected = LocateMarkers(f.frame, f.camera);
    benchmark::DoNotOptimize(EstimateToolPoses(detected.markers, Tools()));
  }
}
BENCHMARK(BM_DetectMatchPoseTwoTools)->Unit(benchmark::kMicrosecond);

// Two flat tape-disc tools like evd-usecase's reference tools (planar: RefineToolPose's disc
// plane ranges and two refinement passes run), 10 mm discs at 450-520 mm, tilted 0.3-0.5 rad.
struct DiscFixture {
  AhatCamera camera{MakeSyntheticAhatCalibration()};
  AhatFrame frame;
  std::vector<ToolGeometry> tools;
};

const DiscFixture& DiscFrame() {
  static const DiscFixture fixture = [] {
    DiscFixture f;
    const Points3d layouts[] = {{{-30, -20, 0.1}, {26, -22, 0.1}, {-17, 21, 0.1}, {31, 16, 0.1}},
                                {{-33, 12, 0.1}, {-8, -30, 0.1}, {24, -14, 0.1}, {18, 27, 0.1}}};
    sim::Scene scene;
    const int wall = scene.AddMaterial(sim::SkinMaterial());
    const int retro = scene.AddMaterial(sim::RetroReflectiveMaterial());
    const Eigen::Quaterniond flip(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()));
    scene.AddObject("wall", sim::PlaneMesh(3000.0, 3000.0), wall, Rigid3d(flip, {0, 0, 700.0}));
    const Rigid3d poses[] = {
        Rigid3d(flip * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()), {-80.0, -20.0, 450.0}),
        Rigid3d(flip * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX()), {90.0, 10.0, 520.0})};
    for (std::size_t t = 0; t < 2; ++t) {
      ToolGeometry geometry = Tool(t == 0 ? "left" : "right", layouts[t]);
      geometry.marker_type = MarkerType::kDisc;
      geometry.marker_diameter_mm = 10.0;
      sim::Tool tool{geometry.name, {}, poses[t]};
      for (const Eigen::Vector3d& p : layouts[t]) {
        tool.markers.push_back(
            sim::DiscMarkerOnSurface({p.x(), p.y(), 0.0}, Eigen::Vector3d::UnitZ(), 10.0, retro));
      }
      scene.AddTool(tool);
      f.tools.push_back(geometry);
    }
    std::mt19937_64 rng(1);
    f.frame = sim::RenderAhatFrame(scene, f.camera, Rigid3d::Identity(), {}, rng).frame;
    return f;
  }();
  return fixture;
}

void BM_DetectMatchPoseTwoDiscTools(benchmark::State& state) {
  const DiscFixture& f = DiscFrame();
  const std::vector<DetectedMarker> markers = LocateMarkers(f.frame, f.camera).markers;
  const std::vector<ToolPoseResult> poses = EstimateToolPoses(markers, f.tools);
  if (markers.size() != 8 || poses[0].status != ToolStatus::kOk ||
      poses[1].status != ToolStatus::kOk) {
    state.SkipWithError("expected 8 markers and both tools posed");
  }
  for (auto _ : state) {
    const MarkerDetectionResult detected = LocateMarkers(f.frame, f.camera);
    benchmark::DoNotOptimize(EstimateToolPoses(detected.markers, f.tools));
  }
}
BENCHMARK(BM_DetectMatchPoseTwoDiscTools)->Unit(benchmark::kMicrosecond);

// Pose estimation alone on the disc tools, without (0) and with (1) f_rf's entrance-angle refit
// (the tape's gain of the simulator's preset, docs/tracking.md 4): what the refit costs.
void BM_EstimateDiscToolPosesEntranceGain(benchmark::State& state) {
  const DiscFixture& f = DiscFrame();
  const std::vector<DetectedMarker> markers = LocateMarkers(f.frame, f.camera).markers;
  ToolPoseOptions options;
  if (state.range(0) != 0)
    options.marker_entrance_gain_mm_per_rad =
        sim::RetroReflectiveMaterial().retro_angle_gain_mm_per_rad;
  for (auto _ : state) benchmark::DoNotOptimize(EstimateToolPoses(markers, f.tools, {}, options));
}
BENCHMARK(BM_EstimateDiscToolPosesEntranceGain)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// The same through ToolTracker (temporal prior and pose filters included).
void BM_TrackTwoTools(benchmark::State& state) {
  const Fixture& f = Frame();
  ToolTracker tracker(Tools());
  double t = 0.0;
  for (auto _ : state) {
    const MarkerDetectionResult detected = LocateMarkers(f.frame, f.camera);
    benchmark::DoNotOptimize(tracker.Track(detected.markers, t += 1.0 / 45.0));
  }
}
BENCHMARK(BM_TrackTwoTools)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace tofnav

BENCHMARK_MAIN();
