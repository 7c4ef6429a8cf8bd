// SPDX-License-Identifier: BSD-3-Clause
// Indexed triangle meshes [mm] with optional per-vertex normals, colours and scalars.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "tofnav/core/point_cloud.hpp"

namespace tofnav {

/// Counter-clockwise triangles seen from outside, indices into `vertices`.
struct TriangleMesh {
  Points3d vertices;  // [mm]
  std::vector<Eigen::Vector3i> triangles;
  Points3d vertex_normals;  // unit, or empty
  std::vector<Rgb8> vertex_colors;
  std::vector<float> vertex_scalars;  // e.g. distance to truth [mm]; empty when absent

  /// Throws PreconditionError on out-of-range indices or attribute size mismatch.
  void CheckConsistent() const;
  /// Area-weighted vertex normals from the triangles.
  Points3d ComputeVertexNormals() const;
  double SurfaceAreaMm2() const;
};

TriangleMesh Transform(const Rigid3d& b_from_a, const TriangleMesh& mesh_in_a);

}  // namespace tofnav
