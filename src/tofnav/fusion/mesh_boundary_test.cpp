// SPDX-License-Identifier: BSD-3-Clause
// Boundary erosion on grids whose rings are known exactly.
#include "tofnav/fusion/mesh_boundary.hpp"

#include <gtest/gtest.h>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

// An n x n grid of squares, two triangles each, (n + 1)^2 vertices 1 mm apart.
TriangleMesh Grid(int n) {
  TriangleMesh mesh;
  for (int y = 0; y <= n; ++y) {
    for (int x = 0; x <= n; ++x) {
      mesh.vertices.emplace_back(x, y, 0.0);
      mesh.vertex_scalars.push_back(static_cast<float>(x + 100 * y));
    }
  }
  const auto id = [n](int x, int y) { return y * (n + 1) + x; };
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      mesh.triangles.emplace_back(id(x, y), id(x + 1, y), id(x + 1, y + 1));
      mesh.triangles.emplace_back(id(x, y), id(x + 1, y + 1), id(x, y + 1));
    }
  }
  return mesh;
}

TEST(ErodeBoundary, TakesOffOneRingOfSquaresPerRing) {
  const TriangleMesh grid = Grid(10);
  for (int rings = 0; rings <= 4; ++rings) {
    const ErodedMesh eroded = ErodeBoundary(grid, rings);
    // Each ring removes every square touching the outer vertex ring: 10 - 2 rings squares wide.
    const int side = 10 - 2 * rings;
    EXPECT_EQ(eroded.mesh.triangles.size(), static_cast<std::size_t>(2 * side * side));
    EXPECT_EQ(eroded.mesh.vertices.size(), static_cast<std::size_t>((side + 1) * (side + 1)));
    EXPECT_EQ(eroded.vertices_removed, grid.vertices.size() - eroded.mesh.vertices.size());
    ASSERT_EQ(eroded.mesh.vertex_scalars.size(), eroded.mesh.vertices.size());
    for (std::size_t v = 0; v < eroded.mesh.vertices.size(); ++v) {  // attributes follow
      const Eigen::Vector3d& p = eroded.mesh.vertices[v];
      EXPECT_EQ(eroded.mesh.vertex_scalars[v], static_cast<float>(p.x() + 100 * p.y()));
      EXPECT_GE(p.x(), rings);
      EXPECT_LE(p.x(), 10 - rings);
    }
  }
  EXPECT_TRUE(ErodeBoundary(grid, 6).mesh.triangles.empty());
}

TEST(ErodeBoundary, LeavesAClosedSurfaceAlone) {
  TriangleMesh tetrahedron;
  tetrahedron.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  tetrahedron.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const ErodedMesh eroded = ErodeBoundary(tetrahedron, 3);
  EXPECT_EQ(eroded.mesh.triangles.size(), 4u);
  EXPECT_EQ(eroded.vertices_removed, 0u);
  EXPECT_THROW(ErodeBoundary(tetrahedron, -1), PreconditionError);
}

}  // namespace
}  // namespace tofnav
