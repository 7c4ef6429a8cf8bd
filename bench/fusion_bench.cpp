// SPDX-License-Identifier: BSD-3-Clause
// TSDF fusion of 512 x 512 AHAT frames of an ellipsoid head and marching cubes of the result.
// Targets (docs/reconstruction.md 6.4): <= 3 ms per frame on 2 threads, <= 20 ms marching cubes.
// The Open3D side-by-side comparison (libopen3d-dev, optional) is a later step.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cstdint>
#include <random>
#include <vector>

#include "tofnav/fusion/fusion_test_scenes.hpp"
#include "tofnav/fusion/marching_cubes.hpp"
#include "tofnav/fusion/mesh_components.hpp"
#include "tofnav/fusion/tsdf_volume.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"

namespace tofnav {
namespace {

constexpr int kFrames = 64;            // distinct pre-rendered views, cycled
constexpr double kNoiseSigmaMm = 1.0;  // the accuracy case
constexpr double kMaxViewAngleRad = 1.2;

struct HeadScene {
  AhatCamera camera{MakeSyntheticAhatCalibration()};
  EllipsoidHead head;
  std::vector<Rigid3d> poses;
  std::vector<Image<float>> clean;  // noise-free ranges
  std::vector<Image<float>> noisy;  // sigma 1 mm

  HeadScene() {
    poses = FrontPoses(head.centre_in_tool, Eigen::Vector3d(0.2, -1.0, 0.3), kMaxViewAngleRad,
                       kFrames, 42);
    std::mt19937_64 rng(7);
    for (const Rigid3d& pose : poses) {
      clean.push_back(head.Render(camera, pose, 0.0, rng));
      noisy.push_back(head.Render(camera, pose, kNoiseSigmaMm, rng));
    }
  }
};

const HeadScene& Scene() {
  static const HeadScene scene;
  return scene;
}

TsdfOptions HeadOptions() {
  TsdfOptions options;           // 1 mm voxels
  options.truncation_vox = 4.0;  // 4 mm
  return options;
}

/// FNV-1a over every block's key and voxels (52 bits, exact in a double counter): optimisations
/// of the kernel must leave it unchanged.
double VolumeHash(const TsdfVolume& volume) {
  std::uint64_t h = 14695981039346656037ull;
  const auto mix = [&h](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
  };
  for (std::size_t b = 0; b < volume.block_count(); ++b) {
    mix(volume.block_keys()[b].data(), 3 * sizeof(int));
    mix(volume.block(b).tsdf.data(), sizeof(volume.block(b).tsdf));
    mix(volume.block(b).weight.data(), sizeof(volume.block(b).weight));
  }
  return static_cast<double>(h >> 12);
}

double MedianHeadErrorMm(const TriangleMesh& mesh) {
  std::vector<double> errors;
  for (const Eigen::Vector3d& v : mesh.vertices) errors.push_back(Scene().head.DistanceMm(v));
  return MedianAbs(errors);
}

/// Steady-state integration of one frame (blocks already allocated by a first pass).
void BM_IntegrateFrame(benchmark::State& state) {
  const HeadScene& scene = Scene();
  const tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(state.range(0)));
  TsdfVolume volume(HeadOptions(), scene.camera);
  for (int i = 0; i < kFrames; ++i) volume.Integrate(scene.noisy[i], scene.poses[i]);
  std::size_t i = 0;
  double blocks = 0.0, voxels = 0.0;
  for (auto _ : state) {
    const IntegrateResult r = volume.Integrate(scene.noisy[i % kFrames], scene.poses[i % kFrames]);
    blocks += r.blocks_touched;
    voxels += static_cast<double>(r.voxels_updated);
    ++i;
  }
  state.counters["blocks/frame"] = blocks / static_cast<double>(i);
  state.counters["Mvox_updated/frame"] = voxels / static_cast<double>(i) / 1e6;
  TsdfVolume check(HeadOptions(), scene.camera);  // a fixed sequence, whatever the iterations
  for (int k = 0; k < 2 * kFrames; ++k)
    check.Integrate(scene.noisy[k % kFrames], scene.poses[k % kFrames]);
  state.counters["volume_hash"] = VolumeHash(check);
}
BENCHMARK(BM_IntegrateFrame)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// Marching cubes over the occupied blocks of the fused head, then its largest component.
void BM_ExtractHead(benchmark::State& state) {
  const HeadScene& scene = Scene();
  TsdfVolume volume(HeadOptions(), scene.camera);
  for (int i = 0; i < kFrames; ++i) volume.Integrate(scene.noisy[i], scene.poses[i]);
  const tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(state.range(0)));
  TriangleMesh mesh;
  for (auto _ : state) {
    mesh = ExtractIsoSurface(volume);
    benchmark::DoNotOptimize(mesh.vertices.data());
  }
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
  state.counters["blocks"] = static_cast<double>(volume.block_count());
}
BENCHMARK(BM_ExtractHead)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_LargestComponentHead(benchmark::State& state) {
  const HeadScene& scene = Scene();
  TsdfVolume volume(HeadOptions(), scene.camera);
  for (int i = 0; i < kFrames; ++i) volume.Integrate(scene.noisy[i], scene.poses[i]);
  const TriangleMesh mesh = ExtractIsoSurface(volume);
  for (auto _ : state) benchmark::DoNotOptimize(LargestConnectedComponent(mesh).vertices.data());
}
BENCHMARK(BM_LargestComponentHead)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The acceptance run: 1000 frames (fresh sigma = 1 mm noise on each, added outside the
/// timed region) fused on the given threads, then meshed; reports the median distance of the
/// mesh to the true ellipsoid. Every 100th frame has no pose (tool not tracked) and is skipped.
void BM_Fuse1000Frames(benchmark::State& state) {
  const HeadScene& scene = Scene();
  const tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(state.range(0)));
  double median_error_mm = 0.0, triangles = 0.0, skipped = 0.0;
  for (auto _ : state) {
    TsdfVolume volume(HeadOptions(), scene.camera);
    std::mt19937_64 rng(1000);
    std::normal_distribution<float> noise(0.0f, static_cast<float>(kNoiseSigmaMm));
    Image<float> frame;
    for (int i = 0; i < 1000; ++i) {
      state.PauseTiming();
      frame = scene.clean[static_cast<std::size_t>(i % kFrames)];
      for (float& d : frame.pixels()) d = d > 0.0f ? d + noise(rng) : 0.0f;
      const std::optional<Rigid3d> pose =
          i % 100 == 99 ? std::nullopt
                        : std::optional(scene.poses[static_cast<std::size_t>(i % kFrames)]);
      state.ResumeTiming();
      volume.Integrate(frame, pose);
    }
    state.PauseTiming();
    const TriangleMesh mesh = LargestConnectedComponent(ExtractIsoSurface(volume));
    median_error_mm = MedianHeadErrorMm(mesh);
    triangles = static_cast<double>(mesh.triangles.size());
    skipped = volume.frames_skipped();
    state.ResumeTiming();
  }
  state.counters["median_error_mm"] = median_error_mm;
  state.counters["triangles"] = triangles;
  state.counters["frames_skipped"] = skipped;
}
BENCHMARK(BM_Fuse1000Frames)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
}  // namespace tofnav

BENCHMARK_MAIN();
