// SPDX-License-Identifier: BSD-3-Clause
// Indexed triangle meshes.
#include "tofnav/core/triangle_mesh.hpp"

#include "tofnav/core/require.hpp"

namespace tofnav {

void TriangleMesh::CheckConsistent() const {
  const std::size_t n = vertices.size();
  Require(vertex_normals.empty() || vertex_normals.size() == n,
          "mesh: normals count != vertex count");
  Require(vertex_colors.empty() || vertex_colors.size() == n, "mesh: colors count != vertex count");
  Require(vertex_scalars.empty() || vertex_scalars.size() == n,
          "mesh: scalars count != vertex count");
  for (const Eigen::Vector3i& t : triangles) {
    Require((t.array() >= 0).all() && (t.array() < static_cast<int>(n)).all(),
            "mesh: triangle index out of range");
  }
}

Points3d TriangleMesh::ComputeVertexNormals() const {
  CheckConsistent();
  Points3d normals(vertices.size(), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& t : triangles) {
    // The unnormalised cross product weights each face by twice its area.
    const Eigen::Vector3d face =
        (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]);
    for (int k = 0; k < 3; ++k) normals[t[k]] += face;
  }
  for (Eigen::Vector3d& n : normals) {
    const double length = n.norm();
    n = length > 0.0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero();
  }
  return normals;
}

double TriangleMesh::SurfaceAreaMm2() const {
  double area = 0.0;
  for (const Eigen::Vector3i& t : triangles) {
    area += 0.5 * (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]).norm();
  }
  return area;
}

TriangleMesh Transform(const Rigid3d& b_from_a, const TriangleMesh& mesh_in_a) {
  mesh_in_a.CheckConsistent();
  TriangleMesh out = mesh_in_a;
  out.vertices = Transform(b_from_a, mesh_in_a.vertices);
  for (Eigen::Vector3d& n : out.vertex_normals) n = b_from_a.rotation * n;
  return out;
}

}  // namespace tofnav
