// SPDX-License-Identifier: BSD-3-Clause
// Test-only mesh checks: edge manifoldness, orientation, duplicate vertices.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <map>
#include <set>
#include <tuple>
#include <utility>

#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav {

struct EdgeCounts {
  int boundary = 0;      // undirected edges used by one triangle
  int non_manifold = 0;  // used by three or more
  int misoriented = 0;   // shared by two triangles that traverse it in the same direction
};

inline EdgeCounts CountEdges(const TriangleMesh& mesh) {
  std::map<std::pair<int, int>, std::pair<int, int>> uses;  // (lo, hi) -> (forward, backward)
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      auto& use = uses[{std::min(a, b), std::max(a, b)}];
      (a < b ? use.first : use.second)++;
    }
  }
  EdgeCounts counts;
  for (const auto& [edge, use] : uses) {
    const int total = use.first + use.second;
    if (total == 1) ++counts.boundary;
    if (total > 2) ++counts.non_manifold;
    if (total == 2 && use.first != 1) ++counts.misoriented;
  }
  return counts;
}

/// Number of vertices whose exact position another vertex also has.
inline int CountDuplicateVertices(const TriangleMesh& mesh) {
  std::set<std::tuple<double, double, double>> seen;
  int duplicates = 0;
  for (const Eigen::Vector3d& v : mesh.vertices) {
    if (!seen.emplace(v.x(), v.y(), v.z()).second) ++duplicates;
  }
  return duplicates;
}

inline bool SameMesh(const TriangleMesh& a, const TriangleMesh& b) {
  const auto same = [](const auto& p, const auto& q) { return p == q; };  // exact
  return std::equal(a.vertices.begin(), a.vertices.end(), b.vertices.begin(), b.vertices.end(),
                    same) &&
         std::equal(a.triangles.begin(), a.triangles.end(), b.triangles.begin(), b.triangles.end(),
                    same);
}

}  // namespace tofnav
