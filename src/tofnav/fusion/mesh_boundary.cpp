// SPDX-License-Identifier: BSD-3-Clause
// The open boundary of a fused surface, where it is least reliable, taken off ring by ring.
#include "tofnav/fusion/mesh_boundary.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "tofnav/core/require.hpp"
#include "tofnav/fusion/mesh_components.hpp"

namespace tofnav {
namespace {

// Marks the vertices on an edge that only one of `triangles` has.
std::vector<char> BoundaryVertices(const std::vector<Eigen::Vector3i>& triangles,
                                   std::size_t vertex_count) {
  std::vector<std::uint64_t> edges;
  edges.reserve(3 * triangles.size());
  for (const Eigen::Vector3i& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::uint64_t>(t[k]);
      const auto b = static_cast<std::uint64_t>(t[(k + 1) % 3]);
      edges.push_back(std::min(a, b) << 32 | std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<char> on_boundary(vertex_count, 0);
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) {
      on_boundary[static_cast<std::size_t>(edges[i] >> 32)] = 1;
      on_boundary[static_cast<std::size_t>(edges[i] & 0xffffffffu)] = 1;
    }
    i = j;
  }
  return on_boundary;
}

}  // namespace

ErodedMesh ErodeBoundary(const TriangleMesh& mesh, int rings) {
  mesh.CheckConsistent();
  Require(rings >= 0, "ErodeBoundary: rings must be >= 0");
  std::vector<Eigen::Vector3i> triangles = mesh.triangles;
  for (int ring = 0; ring < rings && !triangles.empty(); ++ring) {
    const std::vector<char> boundary = BoundaryVertices(triangles, mesh.vertices.size());
    std::erase_if(triangles, [&](const Eigen::Vector3i& t) {
      return boundary[static_cast<std::size_t>(t[0])] || boundary[static_cast<std::size_t>(t[1])] ||
             boundary[static_cast<std::size_t>(t[2])];
    });
  }
  ErodedMesh out;
  out.mesh = WithTriangles(mesh, triangles);
  out.vertices_removed = mesh.vertices.size() - out.mesh.vertices.size();
  return out;
}

}  // namespace tofnav
