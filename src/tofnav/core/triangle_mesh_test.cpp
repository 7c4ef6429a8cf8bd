// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/core/triangle_mesh.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

TriangleMesh UnitSquare() {  // z = 0, normal +z, 10 mm side
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

TEST(TriangleMesh, AreaAndNormals) {
  const TriangleMesh mesh = UnitSquare();
  EXPECT_DOUBLE_EQ(mesh.SurfaceAreaMm2(), 100.0);
  for (const Eigen::Vector3d& n : mesh.ComputeVertexNormals()) {
    EXPECT_LT((n - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  }
}

TEST(TriangleMesh, RejectsBadIndex) {
  TriangleMesh mesh = UnitSquare();
  mesh.triangles.push_back({0, 1, 4});
  EXPECT_THROW(mesh.CheckConsistent(), PreconditionError);
}

TEST(TriangleMesh, TransformRotatesNormals) {
  TriangleMesh mesh = UnitSquare();
  mesh.vertex_normals = mesh.ComputeVertexNormals();
  const Rigid3d b_from_a(
      Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(0, 0, 5));
  const TriangleMesh moved = Transform(b_from_a, mesh);
  EXPECT_LT((moved.vertex_normals[0] - Eigen::Vector3d(0, -1, 0)).norm(), 1e-12);
  EXPECT_LT((moved.vertices[2] - Eigen::Vector3d(10, 0, 15)).norm(), 1e-12);
  EXPECT_NEAR(moved.SurfaceAreaMm2(), 100.0, 1e-9);
}

}  // namespace
}  // namespace tofnav
