// SPDX-License-Identifier: BSD-3-Clause
// Closest points on triangles and meshes against analytic answers and brute force.
#include "tofnav/fusion/surface_distance.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <random>

namespace tofnav {
namespace {

constexpr double kExactTolMm = 1e-9;  // closed-form arithmetic on mm-sized values

TEST(ClosestPointOnTriangle, FaceEdgeAndVertexRegions) {
  const Eigen::Vector3d a(0, 0, 0), b(10, 0, 0), c(0, 10, 0);
  // Above the face: the foot of the perpendicular.
  EXPECT_LE((ClosestPointOnTriangle({2, 3, 5}, a, b, c) - Eigen::Vector3d(2, 3, 0)).norm(),
            kExactTolMm);
  // Beyond edge AB (y < 0): projected onto the edge.
  EXPECT_LE((ClosestPointOnTriangle({4, -3, 1}, a, b, c) - Eigen::Vector3d(4, 0, 0)).norm(),
            kExactTolMm);
  // Beyond the hypotenuse BC: its midpoint for a point on the bisector.
  EXPECT_LE((ClosestPointOnTriangle({8, 8, 0}, a, b, c) - Eigen::Vector3d(5, 5, 0)).norm(),
            kExactTolMm);
  // Vertex regions.
  EXPECT_LE((ClosestPointOnTriangle({-1, -2, 3}, a, b, c) - a).norm(), kExactTolMm);
  EXPECT_LE((ClosestPointOnTriangle({14, -1, 0}, a, b, c) - b).norm(), kExactTolMm);
  EXPECT_LE((ClosestPointOnTriangle({-1, 13, 2}, a, b, c) - c).norm(), kExactTolMm);
}

TriangleMesh Square(double half_mm) {  // z = 0, normal +z (counter-clockwise seen from +z)
  TriangleMesh m;
  m.vertices = {{-half_mm, -half_mm, 0},
                {half_mm, -half_mm, 0},
                {half_mm, half_mm, 0},
                {-half_mm, half_mm, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

TEST(SurfaceDistance, SignedDistanceToAPlaneAndSearchRadius) {
  const SurfaceDistance index(Square(50.0), 4.0);
  const std::optional<SurfacePoint> above = index.Closest({3.0, -7.0, 2.5}, 10.0);
  ASSERT_TRUE(above.has_value());
  EXPECT_NEAR(above->distance_mm, 2.5, kExactTolMm);
  EXPECT_NEAR(above->signed_distance_mm, 2.5, kExactTolMm);
  const std::optional<SurfacePoint> below = index.Closest({3.0, -7.0, -1.25}, 10.0);
  ASSERT_TRUE(below.has_value());
  EXPECT_NEAR(below->signed_distance_mm, -1.25, kExactTolMm);
  EXPECT_FALSE(index.Closest({0.0, 0.0, 12.0}, 10.0).has_value());  // beyond the radius
}

TEST(SurfaceDistance, MatchesBruteForceOnARandomMesh) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> pos(-40.0, 40.0), off(-6.0, 6.0);
  TriangleMesh mesh;
  for (int t = 0; t < 300; ++t) {  // small random triangles in a box
    const Eigen::Vector3d c(pos(rng), pos(rng), pos(rng));
    for (int k = 0; k < 3; ++k)
      mesh.vertices.push_back(c + Eigen::Vector3d(off(rng), off(rng), off(rng)));
    mesh.triangles.emplace_back(3 * t, 3 * t + 1, 3 * t + 2);
  }
  const SurfaceDistance index(mesh, 3.0);
  constexpr double kRadiusMm = 12.0;
  int found = 0;
  for (int q = 0; q < 400; ++q) {
    const Eigen::Vector3d p(pos(rng), pos(rng), pos(rng));
    double best = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3i& t : mesh.triangles) {
      const Eigen::Vector3d c =
          ClosestPointOnTriangle(p, mesh.vertices[static_cast<std::size_t>(t[0])],
                                 mesh.vertices[static_cast<std::size_t>(t[1])],
                                 mesh.vertices[static_cast<std::size_t>(t[2])]);
      best = std::min(best, (p - c).norm());
    }
    const std::optional<SurfacePoint> r = index.Closest(p, kRadiusMm);
    if (best <= kRadiusMm) {
      ASSERT_TRUE(r.has_value()) << q;
      EXPECT_NEAR(r->distance_mm, best, kExactTolMm) << q;
      ++found;
    } else {
      EXPECT_FALSE(r.has_value()) << q;
    }
  }
  EXPECT_GT(found, 100);  // the test exercises both branches
}

}  // namespace
}  // namespace tofnav
