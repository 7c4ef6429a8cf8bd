// SPDX-License-Identifier: BSD-3-Clause
// Side by side: our TSDF fusion of AHAT frames vs Open3D 0.16's ScalableTSDFVolume fed the same
// frames re-sampled to a pinhole (docs/reconstruction.md 6.2): same 1 mm voxels, 4 mm truncation,
// frames and poses, both on the same threads. Optional: built only when find_package(Open3D)
// succeeds. Threads: ours through TBB, Open3D through OpenMP, both set to the argument.
#include <benchmark/benchmark.h>
#include <omp.h>
#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/pipelines/integration/ScalableTSDFVolume.h>
#include <tbb/global_control.h>
#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "tofnav/fusion/fusion_test_scenes.hpp"
#include "tofnav/fusion/marching_cubes.hpp"
#include "tofnav/fusion/tsdf_volume.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"

namespace tofnav {
namespace {

constexpr int kFrames = 64;  // distinct views, cycled
constexpr double kVoxelMm = 1.0, kTruncationMm = 4.0, kNoiseSigmaMm = 1.0;
constexpr int kPinholeSize = 512;
constexpr double kPinholeFocalPx = 180.0;  // +-55 deg: the useful part of the AHAT's view

using Clock = std::chrono::steady_clock;

/// CPU time of the whole process (every thread) [s]: under load, wall times mostly measure the
/// other processes, CPU times much less (with OMP_WAIT_POLICY=passive, so that Open3D's OpenMP
/// workers sleep instead of spinning between its parallel loops).
double ProcessCpuS() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Nearest-neighbour re-sampling of AHAT radial range to pinhole z-depth [m] (hl2ss-style).
struct PinholeResampler {
  std::vector<int> source;      // AHAT pixel index per pinhole pixel, -1 outside the view
  std::vector<float> z_factor;  // z / range along the pinhole ray = 1 / |(x, y, 1)|

  explicit PinholeResampler(const AhatCamera& camera) {
    const double c = 0.5 * (kPinholeSize - 1);
    for (int j = 0; j < kPinholeSize; ++j) {
      for (int i = 0; i < kPinholeSize; ++i) {
        const Eigen::Vector3d ray((i - c) / kPinholeFocalPx, (j - c) / kPinholeFocalPx, 1.0);
        const std::optional<Eigen::Vector2d> uv = camera.Project(ray);
        int index = -1;
        if (uv) {
          const int u = static_cast<int>(std::lround(uv->x()));
          const int v = static_cast<int>(std::lround(uv->y()));
          if (camera.IsValid(u, v)) index = v * camera.width() + u;
        }
        source.push_back(index);
        z_factor.push_back(static_cast<float>(1.0 / ray.norm()));
      }
    }
  }

  void Resample(const Image<float>& range_mm, open3d::geometry::Image& depth_m) const {
    float* out = depth_m.PointerAs<float>();
    for (std::size_t p = 0; p < source.size(); ++p) {
      const float r = source[p] < 0 ? 0.0f : range_mm.data()[source[p]];
      out[p] = r * z_factor[p] * 1e-3f;
    }
  }
};

struct Scene {
  AhatCamera camera{MakeSyntheticAhatCalibration()};
  EllipsoidHead head;
  std::vector<Rigid3d> poses;
  std::vector<Image<float>> frames;  // noisy AHAT ranges
  PinholeResampler resampler{camera};

  Scene() {
    poses = FrontPoses(head.centre_in_tool, Eigen::Vector3d(0.2, -1.0, 0.3), 1.2, kFrames, 42);
    std::mt19937_64 rng(7);
    for (const Rigid3d& pose : poses)
      frames.push_back(head.Render(camera, pose, kNoiseSigmaMm, rng));
  }
};

const Scene& TheScene() {
  static const Scene scene;
  return scene;
}

Eigen::Matrix4d ExtrinsicMetres(const Rigid3d& tool_from_ahat) {  // world (tool) -> camera
  Eigen::Matrix4d m = tool_from_ahat.Inverse().ToMatrix();
  m.block<3, 1>(0, 3) *= 1e-3;
  return m;
}

double MedianErrorMm(const std::vector<Eigen::Vector3d>& vertices_mm) {
  std::vector<double> errors;
  for (const Eigen::Vector3d& v : vertices_mm) errors.push_back(TheScene().head.DistanceMm(v));
  return MedianAbs(errors);
}

/// One iteration = one frame into both volumes, each timed on its own; after the loop both are
/// meshed (untimed) and compared with the true ellipsoid.
void BM_SideBySide(benchmark::State& state) {
  const Scene& scene = TheScene();
  const auto threads = static_cast<std::size_t>(state.range(0));
  const tbb::global_control control(tbb::global_control::max_allowed_parallelism, threads);
  omp_set_num_threads(static_cast<int>(threads));
  TsdfOptions options;
  options.voxel_size_mm = kVoxelMm;
  options.truncation_vox = kTruncationMm / kVoxelMm;
  TsdfVolume ours(options, scene.camera);
  open3d::pipelines::integration::ScalableTSDFVolume theirs(
      kVoxelMm * 1e-3, kTruncationMm * 1e-3,
      open3d::pipelines::integration::TSDFVolumeColorType::NoColor, 16, 4);
  const open3d::camera::PinholeCameraIntrinsic intrinsic(
      kPinholeSize, kPinholeSize, kPinholeFocalPx, kPinholeFocalPx, 0.5 * (kPinholeSize - 1),
      0.5 * (kPinholeSize - 1));
  open3d::geometry::RGBDImage rgbd;
  rgbd.color_.Prepare(kPinholeSize, kPinholeSize, 3, 1);
  rgbd.depth_.Prepare(kPinholeSize, kPinholeSize, 1, 4);
  double ours_s = 0.0, theirs_s = 0.0, resample_s = 0.0, ours_cpu_s = 0.0, theirs_cpu_s = 0.0;
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t f = i++ % kFrames;
    Clock::time_point t = Clock::now();
    double c = ProcessCpuS();
    ours.Integrate(scene.frames[f], scene.poses[f]);
    const double a = std::chrono::duration<double>(Clock::now() - t).count();
    ours_cpu_s += ProcessCpuS() - c;
    t = Clock::now();
    scene.resampler.Resample(scene.frames[f], rgbd.depth_);
    const double r = std::chrono::duration<double>(Clock::now() - t).count();
    t = Clock::now();
    c = ProcessCpuS();
    theirs.Integrate(rgbd, intrinsic, ExtrinsicMetres(scene.poses[f]));
    const double b = std::chrono::duration<double>(Clock::now() - t).count();
    theirs_cpu_s += ProcessCpuS() - c;
    ours_s += a;
    resample_s += r;
    theirs_s += b;
    state.SetIterationTime(a + b);
  }
  const double n = static_cast<double>(i);
  state.counters["tofnav_ms"] = 1e3 * ours_s / n;
  state.counters["open3d_ms"] = 1e3 * theirs_s / n;
  state.counters["resample_ms"] = 1e3 * resample_s / n;
  state.counters["ratio"] = theirs_s / ours_s;
  state.counters["tofnav_cpu_ms"] = 1e3 * ours_cpu_s / n;
  state.counters["open3d_cpu_ms"] = 1e3 * theirs_cpu_s / n;
  state.counters["cpu_ratio"] = theirs_cpu_s / ours_cpu_s;
  const TriangleMesh mesh = ExtractIsoSurface(ours);
  const auto o3d = theirs.ExtractTriangleMesh();
  std::vector<Eigen::Vector3d> o3d_mm;
  for (const Eigen::Vector3d& v : o3d->vertices_) o3d_mm.push_back(1e3 * v);
  state.counters["tofnav_tris"] = static_cast<double>(mesh.triangles.size());
  state.counters["open3d_tris"] = static_cast<double>(o3d->triangles_.size());
  state.counters["tofnav_med_mm"] = MedianErrorMm(mesh.vertices);
  state.counters["open3d_med_mm"] = MedianErrorMm(o3d_mm);
}
BENCHMARK(BM_SideBySide)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Iterations(kFrames)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tofnav

// Both libraries run in this one process. After each parallel loop libgomp's workers spin for
// up to ~0.3 s by default (GOMP_SPINCOUNT), so Open3D's idle OpenMP threads keep our TBB threads
// off the cores; with GOMP_SPINCOUNT=3000 Open3D keeps its own speed (measured: 5.7-6.3 ms per
// frame either way) and ours is undisturbed. libgomp reads the variable when it loads, so it is
// set here and the program started again (unless the caller chose an OpenMP wait policy).
int main(int argc, char** argv) {
  if (std::getenv("GOMP_SPINCOUNT") == nullptr && std::getenv("OMP_WAIT_POLICY") == nullptr) {
    setenv("GOMP_SPINCOUNT", "3000", 1);
    execv("/proc/self/exe", argv);  // returns only on failure: go on with the default
    std::fprintf(stderr, "fusion_open3d_bench: could not restart with GOMP_SPINCOUNT=3000\n");
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
