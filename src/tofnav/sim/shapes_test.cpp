// SPDX-License-Identifier: BSD-3-Clause
// Analytic meshes: sizes, volumes, orientation, closedness; the head phantom's proportions.
#include "tofnav/sim/shapes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include "tofnav/sim/head_phantom.hpp"

namespace tofnav::sim {
namespace {

// Signed volume by the divergence theorem: positive for closed, outward-oriented meshes.
double SignedVolumeMm3(const TriangleMesh& mesh) {
  double six_v = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    six_v += mesh.vertices[static_cast<std::size_t>(t[0])].dot(
        mesh.vertices[static_cast<std::size_t>(t[1])].cross(
            mesh.vertices[static_cast<std::size_t>(t[2])]));
  }
  return six_v / 6.0;
}

double LongestEdgeMm(const TriangleMesh& mesh) {
  double longest = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      longest = std::max(longest, (mesh.vertices[static_cast<std::size_t>(t[k])] -
                                   mesh.vertices[static_cast<std::size_t>(t[(k + 1) % 3])])
                                      .norm());
    }
  }
  return longest;
}

// Every directed edge appears once and its reverse once: a closed, consistently oriented mesh.
bool IsClosedByIndex(const TriangleMesh& mesh) {
  std::map<std::pair<int, int>, int> count;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++count[{t[k], t[(k + 1) % 3]}];
  }
  return std::all_of(count.begin(), count.end(), [&](const auto& e) {
    const auto reverse = count.find({e.first.second, e.first.first});
    return e.second == 1 && reverse != count.end() && reverse->second == 1;
  });
}

TEST(Shapes, PlaneAndBoxHaveTheirSizes) {
  const TriangleMesh plane = PlaneMesh(300.0, 200.0);
  EXPECT_DOUBLE_EQ(plane.SurfaceAreaMm2(), 60000.0);
  const Eigen::Vector3d n =
      (plane.vertices[1] - plane.vertices[0]).cross(plane.vertices[2] - plane.vertices[0]);
  EXPECT_GT(n.z(), 0.0);
  const TriangleMesh box = BoxMesh({10.0, 20.0, 30.0});
  EXPECT_TRUE(IsClosedByIndex(box));
  EXPECT_NEAR(SignedVolumeMm3(box), 6000.0, 1e-9);
}

TEST(Shapes, SphereIsClosedWithRadialNormals) {
  constexpr double kRadius = 50.0;
  const TriangleMesh sphere = SphereMesh(kRadius, 64);
  EXPECT_TRUE(IsClosedByIndex(sphere));
  const double exact = 4.0 / 3.0 * std::numbers::pi * std::pow(kRadius, 3);
  EXPECT_NEAR(SignedVolumeMm3(sphere), exact, 0.01 * exact);  // faceting loses < 1 %
  for (std::size_t i = 0; i < sphere.vertices.size(); ++i) {
    EXPECT_NEAR(sphere.vertices[i].norm(), kRadius, 1e-9);
    EXPECT_NEAR((sphere.vertex_normals[i] - sphere.vertices[i] / kRadius).norm(), 0.0, 1e-12);
  }
}

TEST(Shapes, TestShapesHaveThePapersSizes) {
  for (const double size : kTestShapeSizesMm) {
    const TriangleMesh tetra = TestShapeMesh(TestShape::kTriangularPyramid, size);
    EXPECT_NEAR(LongestEdgeMm(tetra), size, 1e-9);
    EXPECT_NEAR(SignedVolumeMm3(tetra), std::pow(size, 3) / (6.0 * std::sqrt(2.0)),
                1e-6 * size * size * size);
    const TriangleMesh frustum = TestShapeMesh(TestShape::kFrustumPyramid, size);
    double extent = 0.0;  // the base side; LongestEdgeMm would see the faces' diagonals
    for (const Eigen::Vector3d& p : frustum.vertices) extent = std::max(extent, 2.0 * p.x());
    EXPECT_NEAR(extent, size, 1e-9);
    const double a1 = size * size, a2 = 0.25 * size * size, h = size / 3.0;
    EXPECT_NEAR(SignedVolumeMm3(frustum), h / 3.0 * (a1 + a2 + std::sqrt(a1 * a2)),
                1e-6 * a1 * size);
    const TriangleMesh dome = TestShapeMesh(TestShape::kHemisphere, size);
    const double r = 0.5 * size, exact = 2.0 / 3.0 * std::numbers::pi * r * r * r;
    EXPECT_NEAR(SignedVolumeMm3(dome), exact, 0.01 * exact);
    double z_max = 0.0, x_max = 0.0;
    for (const Eigen::Vector3d& p : dome.vertices) {
      z_max = std::max(z_max, p.z());
      x_max = std::max(x_max, p.x());
      EXPECT_GE(p.z(), 0.0);
    }
    EXPECT_NEAR(z_max, r, 1e-9);
    EXPECT_NEAR(x_max, r, 1e-9);
  }
}

TEST(HeadPhantom, IsAClosedHeadSizedMeshWithANose) {
  const TriangleMesh head = HeadPhantomMesh({.segments = 64});
  EXPECT_TRUE(IsClosedByIndex(head));
  EXPECT_GT(SignedVolumeMm3(head), 0.0);
  Eigen::Vector3d lo = head.vertices[0], hi = head.vertices[0];
  std::size_t front = 0;
  for (std::size_t i = 0; i < head.vertices.size(); ++i) {
    lo = lo.cwiseMin(head.vertices[i]);
    hi = hi.cwiseMax(head.vertices[i]);
    if (head.vertices[i].y() > head.vertices[front].y()) front = i;
  }
  const Eigen::Vector3d size = hi - lo;
  constexpr double kSizeTolMm = 10.0;  // bumps and the neck cut change the ellipsoid's extent
  EXPECT_NEAR(size.x(), 150.0, kSizeTolMm);
  EXPECT_NEAR(size.y(), 190.0 + 22.0, kSizeTolMm);  // the nose stands out of the face
  EXPECT_NEAR(size.z(), 110.0 + 0.8 * 110.0, kSizeTolMm);
  // The most anterior point is the nose: on the midline, below the eyes.
  EXPECT_NEAR(head.vertices[front].x(), 0.0, 5.0);
  EXPECT_LT(head.vertices[front].z(), 0.0);
  EXPECT_EQ(head.vertex_normals.size(), head.vertices.size());
}

}  // namespace
}  // namespace tofnav::sim
