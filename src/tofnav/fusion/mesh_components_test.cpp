// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/fusion/mesh_components.hpp"

#include <gtest/gtest.h>

#include "tofnav/fusion/marching_cubes.hpp"

namespace tofnav {
namespace {

/// Two disjoint spheres (radii 12 and 6 mm) as one dense SDF (1 mm voxels).
Grid3<float> TwoSpheres(const Eigen::Vector3d& big, const Eigen::Vector3d& small) {
  const Eigen::Vector3i dims(56, 32, 32);
  Grid3<float> grid(dims, 0.0f);
  for (int k = 0; k < dims.z(); ++k) {
    for (int j = 0; j < dims.y(); ++j) {
      for (int i = 0; i < dims.x(); ++i) {
        const Eigen::Vector3d p(i, j, k);
        grid(i, j, k) =
            static_cast<float>(std::min((p - big).norm() - 12.0, (p - small).norm() - 6.0));
      }
    }
  }
  return grid;
}

TEST(LargestConnectedComponent, KeepsTheBigSphereWhicheverComesFirst) {
  const Eigen::Vector3d left(15.2, 15.6, 15.4), right(40.3, 15.5, 15.7);
  for (const bool big_first : {true, false}) {
    const Eigen::Vector3d big = big_first ? left : right;
    const Eigen::Vector3d small = big_first ? right : left;
    const TriangleMesh both = ExtractIsoSurface(TwoSpheres(big, small));
    const TriangleMesh kept = LargestConnectedComponent(both);
    kept.CheckConsistent();
    ASSERT_FALSE(kept.triangles.empty());
    EXPECT_LT(kept.triangles.size(), both.triangles.size());
    for (const Eigen::Vector3d& v : kept.vertices) EXPECT_NEAR((v - big).norm(), 12.0, 0.05);
    // Every vertex of the big sphere survives, and nothing of the small one.
    std::size_t big_vertices = 0;
    for (const Eigen::Vector3d& v : both.vertices)
      big_vertices += std::abs((v - big).norm() - 12.0) < 1.0 ? 1 : 0;
    EXPECT_EQ(kept.vertices.size(), big_vertices);
  }
}

TEST(LargestConnectedComponent, KeepsAttributesAndOrder) {
  TriangleMesh mesh;  // a lone triangle (vertices 0, 2, 4) and a two-triangle strip (1, 3, 5, 6)
  for (int i = 0; i < 7; ++i) mesh.vertices.emplace_back(i, i * i, 0.0);
  mesh.vertex_scalars = {0.f, 1.f, 2.f, 3.f, 4.f, 5.f, 6.f};
  mesh.triangles = {{0, 2, 4}, {1, 3, 5}, {3, 6, 5}};
  const TriangleMesh kept = LargestConnectedComponent(mesh);
  ASSERT_EQ(kept.vertices.size(), 4u);
  EXPECT_EQ(kept.vertex_scalars, (std::vector<float>{1.f, 3.f, 5.f, 6.f}));
  ASSERT_EQ(kept.triangles.size(), 2u);
  EXPECT_EQ(kept.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(kept.triangles[1], Eigen::Vector3i(1, 3, 2));
  EXPECT_TRUE(LargestConnectedComponent(TriangleMesh{}).vertices.empty());
}

TEST(ConnectedComponentAround, KeepsTheSurfaceLookedAtNotTheLargestNorAFragment) {
  // The small sphere (radius 6 mm) is what the wearer looked at, beside a bigger one (a drape):
  // a point 1 mm in front of it selects it whole, and nothing of the big one.
  const Eigen::Vector3d big(15.2, 15.6, 15.4), small(40.3, 15.5, 15.7);
  const TriangleMesh both = ExtractIsoSurface(TwoSpheres(big, small));
  const TriangleMesh kept =
      ConnectedComponentAround(both, small + Eigen::Vector3d(0, 0, -7.0), 10.0);
  ASSERT_FALSE(kept.triangles.empty());
  std::size_t small_vertices = 0;
  for (const Eigen::Vector3d& v : both.vertices)
    small_vertices += std::abs((v - small).norm() - 6.0) < 1.0 ? 1 : 0;
  EXPECT_EQ(kept.vertices.size(), small_vertices);
  for (const Eigen::Vector3d& v : kept.vertices) EXPECT_LT((v - small).norm(), 8.0);
  // Between the two, with both within 30 mm, the one with more surface there wins: the big one
  // (a fragment beside the head does not win by being nearest).
  const Eigen::Vector3d between(29.0, 15.5, 15.5);  // 2 mm off the big one, 5 mm off the small
  const TriangleMesh around = ConnectedComponentAround(both, between, 30.0);
  for (const Eigen::Vector3d& v : around.vertices) EXPECT_NEAR((v - big).norm(), 12.0, 0.05);
  // Nothing within the radius: the largest.
  EXPECT_EQ(ConnectedComponentAround(both, Eigen::Vector3d(500, 0, 0), 10.0).vertices.size(),
            LargestConnectedComponent(both).vertices.size());
  EXPECT_TRUE(ConnectedComponentAround(TriangleMesh{}, small, 10.0).vertices.empty());
}

}  // namespace
}  // namespace tofnav
