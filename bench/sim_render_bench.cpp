// SPDX-License-Identifier: BSD-3-Clause
// Frames per second of the AHAT simulator on the synthetic head scene (target >= 10 at 2 x 2
// with multipath on, the realistic default).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "tofnav/sensor/ahat_calibration.hpp"
#include "tofnav/sim/head_phantom.hpp"
#include "tofnav/sim/render.hpp"
#include "tofnav/sim/shapes.hpp"

namespace tofnav::sim {
namespace {

// Head (skin, face towards the camera, 500 mm), 4 forehead stickers, a 4-ball reference tool
// beside it and a wall at 1.5 m that wraps to 445 mm.
Scene HeadScene() {
  Scene scene;
  const int skin = scene.AddMaterial(SkinMaterial());
  const int wall = scene.AddMaterial(DiffuseMaterial(0.5));
  const int retro = scene.AddMaterial(RetroReflectiveMaterial());
  Eigen::Matrix3d ahat_from_head;  // head +y (face) -> ahat -z, head +z (up) -> ahat -y
  ahat_from_head << -1, 0, 0, 0, 0, -1, 0, -1, 0;
  const Rigid3d scene_from_head(Eigen::Quaterniond(ahat_from_head), {0.0, 0.0, 500.0});
  const HeadPhantomOptions head_options;
  scene.AddObject("head", HeadPhantomMesh(head_options), skin, scene_from_head);
  scene.AddObject(
      "wall", PlaneMesh(4000.0, 4000.0), wall,
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX())),
              {0.0, 0.0, 1500.0}));
  Tool stickers{"forehead", {}, scene_from_head};
  const Eigen::Vector3d axes = head_options.semi_axes_mm;
  for (const double azimuth : {-0.35, -0.12, 0.12, 0.35}) {
    const double elevation = 0.45;
    const Eigen::Vector3d unit(std::sin(azimuth) * std::cos(elevation),
                               std::cos(azimuth) * std::cos(elevation), std::sin(elevation));
    const Eigen::Vector3d point = unit.cwiseProduct(axes);
    const Eigen::Vector3d normal = point.cwiseQuotient(axes.cwiseProduct(axes)).normalized();
    stickers.markers.push_back(DiscMarkerOnSurface(point, normal, 10.0, retro, 0.3));
  }
  scene.AddTool(stickers);
  Tool reference{"reference",
                 {},
                 scene_from_head * Rigid3d(Eigen::Quaterniond::Identity(), {110.0, 60.0, 40.0})};
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(50, 0, 0),
                                   Eigen::Vector3d(0, 0, 70), Eigen::Vector3d(35, 0, 110)}) {
    reference.markers.push_back(SphereMarker(p, 11.5, retro));
  }
  scene.AddTool(reference);
  return scene;
}

void BM_RenderHeadScene(benchmark::State& state) {
  const AhatCamera camera(MakeSyntheticAhatCalibration());
  const Scene scene = HeadScene();
  AhatRenderer renderer(scene, camera);
  RenderOptions options;
  options.supersampling = static_cast<int>(state.range(0));
  options.multipath.gain = static_cast<double>(state.range(1));  // 1: realism (the default)
  std::mt19937_64 rng(1);
  int frame = 0;
  for (auto _ : state) {
    // A small head-worn motion per frame: only instance transforms change.
    const Rigid3d scene_from_ahat(
        Eigen::Quaterniond(Eigen::AngleAxisd(0.002 * (frame % 50), Eigen::Vector3d::UnitY())),
        {0.2 * (frame % 50), 0.0, 0.0});
    RenderResult result = renderer.Render(scene, scene_from_ahat, options, rng);
    benchmark::DoNotOptimize(result.frame.range_mm.data());
    ++frame;
  }
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
// "CPU" is the process CPU time over all threads: frames/s on N free cores ~ N * 1000 / CPU ms.
// Args: sub-rays per axis, multipath gain (0 off, 1 on).
BENCHMARK(BM_RenderHeadScene)
    ->Args({1, 1})
    ->Args({2, 0})
    ->Args({2, 1})
    ->Args({4, 1})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

}  // namespace
}  // namespace tofnav::sim

BENCHMARK_MAIN();
