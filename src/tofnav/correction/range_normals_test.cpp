// SPDX-License-Identifier: BSD-3-Clause
// Normals and incidence angles of analytic planes, edges and invalid pixels.
#include "tofnav/correction/range_normals.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "correction_test_scenes.hpp"

namespace tofnav {
namespace {

using testing::CorrectionCamera;

// Float ranges (no rounding): only the curvature of range along the rays over the 5 x 5 smoothing
// window and float arithmetic remain.
constexpr double kExactAngleTolRad = 2e-3;

// The plane's range inside the window [140, 372]^2 (0 elsewhere: keeps unoptimised tests fast).
Image<float> PlaneRange(const testing::TestPlane& plane) {
  const AhatCamera& camera = CorrectionCamera();
  Image<float> range(camera.width(), camera.height());
  for (int v = 140; v <= 372; ++v) {
    for (int u = 140; u <= 372; ++u) {
      if (camera.IsValid(u, v)) {
        range(u, v) = static_cast<float>(plane.Range(camera.PixelRay(u, v).cast<double>()));
      }
    }
  }
  return range;
}

TEST(ComputeRangeNormals, TiltedPlaneGivesItsNormalAndIncidence) {
  const testing::TestPlane plane = testing::TiltedPlane(500.0, 0.6);
  const Image<float> range = PlaneRange(plane);
  const RangeNormals normals = ComputeRangeNormals(range, CorrectionCamera());
  int checked = 0;
  for (int v = 156; v <= 356; v += 20) {
    for (int u = 156; u <= 356; u += 20) {
      const Eigen::Vector3d ray = CorrectionCamera().PixelRay(u, v).cast<double>();
      const Eigen::Vector3d n = normals.normal(u, v).cast<double>();
      EXPECT_NEAR((n + plane.normal).norm(), 0.0, kExactAngleTolRad) << u << "," << v;
      EXPECT_NEAR(normals.incidence_rad(u, v), plane.Incidence(ray), kExactAngleTolRad);
      const std::optional<PixelNormal> one = ComputePixelNormal(range, CorrectionCamera(), u, v);
      ASSERT_TRUE(one.has_value());
      EXPECT_EQ(one->normal, normals.normal(u, v));  // same arithmetic, sparse evaluation
      ++checked;
    }
  }
  EXPECT_EQ(checked, 121);
}

TEST(ComputeRangeNormals, DepthEdgeKeepsEachSidesNormal) {
  // Left half: a frontal plane at 400 mm; right half: a plane tilted 0.5 rad at 600 mm.
  const testing::TestPlane near_plane = testing::TiltedPlane(400.0, 0.0);
  const testing::TestPlane far_plane = testing::TiltedPlane(600.0, 0.5);
  const AhatCamera& camera = CorrectionCamera();
  Image<float> range(camera.width(), camera.height());
  for (int v = 220; v <= 290; ++v) {
    for (int u = 220; u <= 290; ++u) {
      if (!camera.IsValid(u, v)) continue;
      const Eigen::Vector3d ray = camera.PixelRay(u, v).cast<double>();
      range(u, v) = static_cast<float>((u < 256 ? near_plane : far_plane).Range(ray));
    }
  }
  range(250, 250) = 0.0f;  // an invalid pixel beside the edge
  const RangeNormals normals = ComputeRangeNormals(range, camera);
  for (int v = 240; v <= 260; v += 5) {
    for (const int u : {253, 254, 255, 256, 257, 258}) {
      const auto& plane = u < 256 ? near_plane : far_plane;
      const Eigen::Vector3d n = normals.normal(u, v).cast<double>();
      EXPECT_NEAR((n + plane.normal).norm(), 0.0, 5 * kExactAngleTolRad) << u << "," << v;
    }
  }
  EXPECT_TRUE(std::isnan(normals.incidence_rad(250, 250)));
  EXPECT_EQ(normals.normal(250, 250), Eigen::Vector3f::Zero());
}

TEST(ComputeRangeNormals, IsolatedPixelHasNoNormal) {
  const AhatCamera& camera = CorrectionCamera();
  Image<float> range(camera.width(), camera.height());
  range(300, 300) = 500.0f;
  const RangeNormals normals = ComputeRangeNormals(range, camera);
  EXPECT_TRUE(std::isnan(normals.incidence_rad(300, 300)));
}

TEST(ComputeRangeNormals, RejectsBadOptionsAndSizes) {
  RangeNormalOptions options;
  options.difference_step_px = 0;
  EXPECT_THROW(ComputeRangeNormals(Image<float>(512, 512), CorrectionCamera(), options),
               std::invalid_argument);
  EXPECT_THROW(ComputeRangeNormals(Image<float>(10, 10), CorrectionCamera()),
               std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
