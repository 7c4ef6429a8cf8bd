// SPDX-License-Identifier: BSD-3-Clause
// Connected components of a triangle mesh over shared vertices (union-find).
#include "tofnav/fusion/mesh_components.hpp"

#include <numeric>
#include <optional>
#include <vector>

namespace tofnav {
namespace {

/// Union-find with path halving and union by size.
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n), size_(n, 1) {
    std::iota(parent_.begin(), parent_.end(), std::size_t{0});
  }
  std::size_t Find(std::size_t i) {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }
  void Union(std::size_t a, std::size_t b) {
    a = Find(a);
    b = Find(b);
    if (a == b) return;
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
  }

 private:
  std::vector<std::size_t> parent_;
  std::vector<std::size_t> size_;
};

DisjointSets Components(const TriangleMesh& mesh) {
  DisjointSets sets(mesh.vertices.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    sets.Union(static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[1]));
    sets.Union(static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[2]));
  }
  return sets;
}

// The triangles (and their vertices) of the component with root `root`, in their order.
TriangleMesh KeepComponent(const TriangleMesh& mesh, DisjointSets& sets, std::size_t root) {
  std::vector<Eigen::Vector3i> kept;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    if (sets.Find(static_cast<std::size_t>(t[0])) == root) kept.push_back(t);
  }
  return WithTriangles(mesh, kept);
}

}  // namespace

TriangleMesh WithTriangles(const TriangleMesh& mesh,
                           const std::vector<Eigen::Vector3i>& triangles) {
  std::vector<int> remap(mesh.vertices.size(), -1);
  for (const Eigen::Vector3i& t : triangles) {
    for (int k = 0; k < 3; ++k) remap[static_cast<std::size_t>(t[k])] = 0;
  }
  TriangleMesh out;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (remap[v] < 0) continue;
    remap[v] = static_cast<int>(out.vertices.size());
    out.vertices.push_back(mesh.vertices[v]);
    if (!mesh.vertex_normals.empty()) out.vertex_normals.push_back(mesh.vertex_normals[v]);
    if (!mesh.vertex_colors.empty()) out.vertex_colors.push_back(mesh.vertex_colors[v]);
    if (!mesh.vertex_scalars.empty()) out.vertex_scalars.push_back(mesh.vertex_scalars[v]);
  }
  out.triangles.reserve(triangles.size());
  for (const Eigen::Vector3i& t : triangles) {
    out.triangles.emplace_back(remap[static_cast<std::size_t>(t[0])],
                               remap[static_cast<std::size_t>(t[1])],
                               remap[static_cast<std::size_t>(t[2])]);
  }
  return out;
}

TriangleMesh LargestConnectedComponent(const TriangleMesh& mesh) {
  mesh.CheckConsistent();
  if (mesh.triangles.empty()) return {};
  DisjointSets sets = Components(mesh);
  // Triangles per component root; the first triangle met decides ties.
  std::vector<std::size_t> triangles_of(mesh.vertices.size(), 0);
  std::size_t best_root = sets.Find(static_cast<std::size_t>(mesh.triangles.front()[0]));
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const std::size_t root = sets.Find(static_cast<std::size_t>(t[0]));
    if (++triangles_of[root] > triangles_of[best_root]) best_root = root;
  }
  return KeepComponent(mesh, sets, best_root);
}

TriangleMesh ConnectedComponentAround(const TriangleMesh& mesh, const Eigen::Vector3d& point,
                                      double radius_mm) {
  mesh.CheckConsistent();
  if (mesh.triangles.empty()) return {};
  DisjointSets sets = Components(mesh);
  // Triangles per component root within the radius; the first triangle met decides ties.
  std::vector<std::size_t> near_of(mesh.vertices.size(), 0);
  std::optional<std::size_t> best_root;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const auto v = static_cast<std::size_t>(t[0]);
    if ((mesh.vertices[v] - point).norm() > radius_mm) continue;
    const std::size_t root = sets.Find(v);
    if (++near_of[root] > (best_root ? near_of[*best_root] : 0)) best_root = root;
  }
  return best_root ? KeepComponent(mesh, sets, *best_root) : LargestConnectedComponent(mesh);
}

}  // namespace tofnav
