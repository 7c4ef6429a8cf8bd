// SPDX-License-Identifier: BSD-3-Clause
// The open boundary of a fused surface, where it is least reliable, taken off ring by ring.
#pragma once

#include <cstddef>

#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav {

struct ErodedMesh {
  TriangleMesh mesh;
  std::size_t vertices_removed = 0;
};

/// Removes `rings` rings of triangles from the mesh's open boundaries (outer rims and holes):
/// in each ring, every triangle with a vertex on a boundary edge (an edge of exactly one
/// triangle) goes. Vertices and triangles keep their relative order and per-vertex attributes;
/// unused vertices are dropped. A closed mesh is returned unchanged. Throws PreconditionError on
/// an inconsistent mesh or rings < 0.
ErodedMesh ErodeBoundary(const TriangleMesh& mesh, int rings);

}  // namespace tofnav
