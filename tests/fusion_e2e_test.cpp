// SPDX-License-Identifier: BSD-3-Clause
// End to end (slow): an ellipsoid head seen by the 512 x 512 synthetic AHAT camera from 300 to
// 500 mm with range noise sigma = 1 mm, fused at 1 mm voxels, meshed, largest component.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "tofnav/fusion/fusion_test_scenes.hpp"
#include "tofnav/fusion/marching_cubes.hpp"
#include "tofnav/fusion/mesh_components.hpp"
#include "tofnav/fusion/tsdf_volume.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"

namespace tofnav {
namespace {

// The acceptance bound: median reconstruction error <= 0.3 mm at depth noise sigma 1 mm
// (the paper reports 0.46-0.56 mm on phantoms).
constexpr double kMedianErrorTolMm = 0.3;
constexpr int kFrames = 80;

TEST(FusionEndToEnd, NoisyHeadMedianErrorBelowPointThreeMm) {
  const AhatCamera camera(MakeSyntheticAhatCalibration());
  const EllipsoidHead head;
  const std::vector<Rigid3d> poses =
      FrontPoses(head.centre_in_tool, Eigen::Vector3d(0.2, -1.0, 0.3), 1.2, kFrames, 42);
  TsdfOptions options;  // 1 mm voxels
  options.truncation_vox = 4.0;
  TsdfVolume volume(options, camera);
  std::mt19937_64 rng(5);
  for (int i = 0; i < kFrames; ++i) {
    const std::optional<Rigid3d> pose =
        i % 40 == 39 ? std::nullopt : std::optional(poses[static_cast<std::size_t>(i)]);
    volume.Integrate(head.Render(camera, poses[static_cast<std::size_t>(i)], 1.0, rng), pose);
  }
  EXPECT_EQ(volume.frames_skipped(), kFrames / 40);
  EXPECT_EQ(volume.frames_integrated(), kFrames - kFrames / 40);
  const TriangleMesh mesh = LargestConnectedComponent(ExtractIsoSurface(volume));
  ASSERT_GT(mesh.triangles.size(), 50000u);
  std::vector<double> errors;
  for (const Eigen::Vector3d& v : mesh.vertices) errors.push_back(head.DistanceMm(v));
  const double median = MedianAbs(errors);
  RecordProperty("median_error_mm", std::to_string(median));
  EXPECT_LE(median, kMedianErrorTolMm);
}

}  // namespace
}  // namespace tofnav
