// SPDX-License-Identifier: BSD-3-Clause
// Internal to imaging/: smoothing and decimation of the skin mesh.
#pragma once

#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav {

/// Taubin's lambda|mu smoothing (lambda 0.5, mu -0.53) over the mesh's edges: removes the
/// marching-cubes staircase without shrinking. Normals are dropped (recompute them).
void SmoothTaubin(TriangleMesh& mesh, int iterations);

/// Vertex clustering: the vertices of each cubic cell of `cell_mm` merge into their mean;
/// triangles that collapse or repeat are dropped, unused vertices removed. Normals are dropped.
void DecimateByClustering(TriangleMesh& mesh, double cell_mm);

}  // namespace tofnav
