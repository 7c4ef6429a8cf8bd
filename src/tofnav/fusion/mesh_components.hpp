// SPDX-License-Identifier: BSD-3-Clause
// Connected components of a triangle mesh over shared vertices, and subsets of its triangles.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav {

/// The mesh reduced to `triangles` (indices into mesh.vertices): the vertices they use, in their
/// order, with their per-vertex attributes; the triangles reindexed, in the given order.
TriangleMesh WithTriangles(const TriangleMesh& mesh, const std::vector<Eigen::Vector3i>& triangles);

/// The connected component (triangles joined through shared vertices, union-find) with the most
/// triangles; ties go to the component of the earliest triangle. Vertices and triangles keep their
/// relative order and per-vertex attributes; unused vertices are dropped.
TriangleMesh LargestConnectedComponent(const TriangleMesh& mesh);

/// The connected component with the most triangles within `radius_mm` of `point` (the surface
/// around what a wearer looked at: not a larger drape beside it, nor a small fragment in front
/// of it), kept as LargestConnectedComponent keeps its component; the largest when no triangle
/// lies that close.
TriangleMesh ConnectedComponentAround(const TriangleMesh& mesh, const Eigen::Vector3d& point,
                                      double radius_mm);

}  // namespace tofnav
