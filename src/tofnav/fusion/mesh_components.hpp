// SPDX-License-Identifier: BSD-3-Clause
// Connected components of a triangle mesh over shared vertices.
#pragma once

#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav {

/// The connected component (triangles joined through shared vertices, union-find) with the most
/// triangles; ties go to the component of the earliest triangle. Vertices and triangles keep their
/// relative order and per-vertex attributes; unused vertices are dropped.
TriangleMesh LargestConnectedComponent(const TriangleMesh& mesh);

}  // namespace tofnav
