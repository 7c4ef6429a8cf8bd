// SPDX-License-Identifier: BSD-3-Clause
// Skin mesh smoothing (Taubin 1995) and decimation by vertex clustering (Rossignac & Borrel 1993).
#include "tofnav/imaging/skin_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <tuple>
#include <vector>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr double kTaubinLambda = 0.5, kTaubinMu = -0.53;  // Taubin's pass band ~0.1

/// Sorted unique neighbours of each vertex (compressed rows).
struct Adjacency {
  std::vector<std::size_t> offsets;
  std::vector<int> neighbours;
};

Adjacency BuildAdjacency(const TriangleMesh& mesh) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(mesh.triangles.size() * 6);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int a = 0; a < 3; ++a) {
      edges.emplace_back(t[a], t[(a + 1) % 3]);
      edges.emplace_back(t[(a + 1) % 3], t[a]);
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  Adjacency adjacency;
  adjacency.offsets.assign(mesh.vertices.size() + 1, 0);
  for (const auto& [from, to] : edges) ++adjacency.offsets[static_cast<std::size_t>(from) + 1];
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    adjacency.offsets[v + 1] += adjacency.offsets[v];
  }
  adjacency.neighbours.reserve(edges.size());
  for (const auto& edge : edges) adjacency.neighbours.push_back(edge.second);
  return adjacency;
}

void LaplacianStep(const Adjacency& adjacency, double factor, Points3d& vertices) {
  const Points3d before = vertices;
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    const std::size_t begin = adjacency.offsets[v], end = adjacency.offsets[v + 1];
    if (begin == end) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t n = begin; n < end; ++n) {
      mean += before[static_cast<std::size_t>(adjacency.neighbours[n])];
    }
    mean /= static_cast<double>(end - begin);
    vertices[v] += factor * (mean - before[v]);
  }
}

}  // namespace

void SmoothTaubin(TriangleMesh& mesh, int iterations) {
  Require(iterations >= 0, "SmoothTaubin: iterations must be >= 0");
  if (iterations == 0) return;
  const Adjacency adjacency = BuildAdjacency(mesh);
  for (int i = 0; i < iterations; ++i) {
    LaplacianStep(adjacency, kTaubinLambda, mesh.vertices);
    LaplacianStep(adjacency, kTaubinMu, mesh.vertices);
  }
  mesh.vertex_normals.clear();
}

void DecimateByClustering(TriangleMesh& mesh, double cell_mm) {
  Require(std::isfinite(cell_mm) && cell_mm > 0.0, "DecimateByClustering: cell_mm must be > 0");
  using Cell = std::tuple<std::int64_t, std::int64_t, std::int64_t>;
  std::map<Cell, int> cell_index;
  std::vector<int> cluster_of(mesh.vertices.size());
  Points3d sums;
  std::vector<int> counts;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Eigen::Vector3d c = (mesh.vertices[v] / cell_mm).array().floor();
    const Cell cell{static_cast<std::int64_t>(c.x()), static_cast<std::int64_t>(c.y()),
                    static_cast<std::int64_t>(c.z())};
    const auto [it, inserted] = cell_index.try_emplace(cell, static_cast<int>(sums.size()));
    if (inserted) {
      sums.push_back(Eigen::Vector3d::Zero());
      counts.push_back(0);
    }
    cluster_of[v] = it->second;
  }
  std::set<std::array<int, 3>> seen;
  std::vector<Eigen::Vector3i> triangles;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3i c(cluster_of[static_cast<std::size_t>(t[0])],
                            cluster_of[static_cast<std::size_t>(t[1])],
                            cluster_of[static_cast<std::size_t>(t[2])]);
    if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) continue;
    std::array<int, 3> key = {c[0], c[1], c[2]};
    std::rotate(key.begin(), std::min_element(key.begin(), key.end()), key.end());
    if (!seen.insert(key).second) continue;
    triangles.push_back(c);
  }
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    sums[static_cast<std::size_t>(cluster_of[v])] += mesh.vertices[v];
    ++counts[static_cast<std::size_t>(cluster_of[v])];
  }
  std::vector<int> new_index(sums.size(), -1);
  TriangleMesh out;
  for (Eigen::Vector3i& t : triangles) {
    for (int a = 0; a < 3; ++a) {
      int& index = new_index[static_cast<std::size_t>(t[a])];
      if (index < 0) {
        index = static_cast<int>(out.vertices.size());
        out.vertices.push_back(sums[static_cast<std::size_t>(t[a])] /
                               counts[static_cast<std::size_t>(t[a])]);
      }
      t[a] = index;
    }
    out.triangles.push_back(t);
  }
  mesh = std::move(out);
}

}  // namespace tofnav
