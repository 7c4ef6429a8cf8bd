// SPDX-License-Identifier: BSD-3-Clause
// Identification (Eq. 7) on 1000 frames: the solver alone on synthetic patches, and the CLI's
// whole path from AHAT frames (segmentation, head region, sampling, both stages with the skin).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include "correction_test_scenes.hpp"
#include "tofnav/correction/head_region.hpp"
#include "tofnav/correction/identification.hpp"
#include "tofnav/correction/initial_pose.hpp"
#include "tofnav/correction/multipath_correction.hpp"
#include "tofnav/correction/range_normals.hpp"
#include "tofnav/sim/scenario_builtins.hpp"
#include "tofnav/sim/simulator.hpp"

namespace tofnav {
namespace {

// 1000 sphere-head frames at 380-800 mm, 3 markers each with about 160 neighbours (the CLI's
// max_patch_points) and 17 marker points.
std::vector<IdentificationFrame> Frames() {
  DepthErrorModel truth;
  truth.c1_mm = 9.2, truth.c2 = 0.007, truth.c3_mm = 5.5;
  std::vector<IdentificationFrame> frames;
  for (int i = 0; i < 1000; ++i) {
    const double range = 380.0 + 420.0 * (i % 37) / 36.0;
    const Eigen::Vector3d centre =
        Eigen::AngleAxisd(0.02 * (i % 29) - 0.3, Eigen::Vector3d::UnitX()) *
        Eigen::Vector3d(2.0 * (i % 31) - 30.0, 0.0, range);
    frames.push_back(testing::SphereFrame(i, centre, truth, 40, 3.0));
  }
  return frames;
}

void BM_IdentifySmoothness1000Frames(benchmark::State& state) {
  const std::vector<IdentificationFrame> frames = Frames();
  for (auto _ : state) {
    benchmark::DoNotOptimize(IdentifyDepthModel(frames, nullptr, DepthErrorModel{}));
  }
}
BENCHMARK(BM_IdentifySmoothness1000Frames)->Unit(benchmark::kMillisecond)->Iterations(3);

// 40 rendered head-identification frames (the simulator is not timed), cycled to 1000.
struct RenderedRun {
  std::vector<AhatFrame> frames;
  std::unique_ptr<AhatCamera> camera;
  TriangleMesh skin;
};
const RenderedRun& Rendered() {
  static const RenderedRun run = [] {
    sim::Scenario scenario = sim::BuiltinScenario("head-identification");
    scenario.frames = 40;
    RenderedRun r;
    r.skin = scenario.scene.objects[static_cast<std::size_t>(scenario.patient->object)].mesh;
    sim::Simulator simulator(scenario);
    r.camera = std::make_unique<AhatCamera>(simulator.camera());
    while (!simulator.done()) r.frames.push_back(simulator.Next().render.frame);
    return r;
  }();
  return run;
}

// What `tofnav identify --max-frames 1000 [--skin]` does after decoding (default sampling).
void BM_IdentifyCliPath1000Frames(benchmark::State& state) {
  const RenderedRun& run = Rendered();
  const bool with_skin = state.range(0) != 0;
  const SurfaceIndex skin(run.skin);
  std::vector<int> indices(1000);
  for (int i = 0; i < 1000; ++i) indices[static_cast<std::size_t>(i)] = i;
  for (auto _ : state) {
    const std::vector<IdentificationFrame> frames = PrepareIdentificationFrames(
        indices, [&](int i) { return run.frames[static_cast<std::size_t>(i) % run.frames.size()]; },
        *run.camera, MarkerRangeModel{});
    DepthErrorModel model = IdentifyDepthModel(frames, nullptr, DepthErrorModel{});
    if (with_skin) {
      const InitialPoseResult pose = InitialImageFromAhat(frames, skin, model);
      const CorrectnessTarget target{&skin, pose.image_from_ahat};
      model = IdentifyDepthModel(frames, &target, model);
    }
    benchmark::DoNotOptimize(model);
  }
}
BENCHMARK(BM_IdentifyCliPath1000Frames)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->UseRealTime();

// One rendered frame's normals over the whole image (smoothing, differences, incidence angles).
void BM_RangeNormalsFrame(benchmark::State& state) {
  const RenderedRun& run = Rendered();
  const Image<float> range = RangeAsFloat(run.frames[0].range_mm);
  for (auto _ : state) benchmark::DoNotOptimize(ComputeRangeNormals(range, *run.camera));
}
BENCHMARK(BM_RangeNormalsFrame)->Unit(benchmark::kMillisecond)->Repetitions(5);

// One rendered frame's multipath removal with the default options, every pixel wanted (three
// passes: normals, block patches and the patches' exchange each pass).
void BM_RemoveMultipathFrame(benchmark::State& state) {
  const RenderedRun& run = Rendered();
  const AhatFrame& frame = run.frames[0];
  const Image<float> range = RangeAsFloat(frame.range_mm);
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        RemoveMultipath(range, frame.ab, *run.camera, MultipathCorrectionOptions{}));
  }
}
BENCHMARK(BM_RemoveMultipathFrame)->Unit(benchmark::kMillisecond)->Repetitions(5);

// One rendered frame's automatic head region (planes, components, plates, components).
void BM_SelectHeadRegionFrame(benchmark::State& state) {
  const RenderedRun& run = Rendered();
  const Image<float> range = RangeAsFloat(run.frames[0].range_mm);
  for (auto _ : state) benchmark::DoNotOptimize(SelectHeadRegion(range, *run.camera));
}
BENCHMARK(BM_SelectHeadRegionFrame)->Unit(benchmark::kMillisecond)->Repetitions(5);

}  // namespace
}  // namespace tofnav

BENCHMARK_MAIN();
