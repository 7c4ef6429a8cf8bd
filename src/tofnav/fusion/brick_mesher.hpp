// SPDX-License-Identifier: BSD-3-Clause
// Internal: marching cubes over a sparse set of 8^3 bricks of a sampled scalar field.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav {

constexpr int kBrickSide = 8;         // cells per brick side
constexpr int kBrickSamplesSide = 9;  // samples per side: the cells' corners
constexpr int kBrickSamples = 9 * 9 * 9;

/// The samples at lattice points 8 * key + (x, y, z), x, y, z in 0..8, x fastest.
struct BrickSamples {
  std::array<float, kBrickSamples> value;         // field minus the iso value
  std::array<std::uint8_t, kBrickSamples> valid;  // 0: unobserved or outside the field
};

/// A scalar field on an integer lattice, split into bricks of 8^3 cells. A lattice point must
/// load the same value and validity from every brick that contains it.
struct BrickLattice {
  /// Bricks that may hold surface, ascending in (z, y, x), unique. A brick whose owned edges
  /// (from its 8^3 lattice points along +x, +y, +z) cross the surface must be listed.
  std::vector<Eigen::Vector3i> keys;
  /// Fills the samples of brick keys[i]; called concurrently for different i.
  std::function<void(std::size_t, BrickSamples&)> load;
  /// Lattice point -> mm.
  Eigen::Matrix3d linear = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  /// Emit triangles clockwise (seen from the side above the iso value) instead.
  bool flip = false;
};

/// Lorensen & Cline (1987) marching cubes over every cell whose eight corners are valid.
/// Vertices lie on lattice edges (linear interpolation of the value) and are shared: each brick
/// owns the edges leaving its own lattice points, so a vertex exists once however many cells and
/// bricks use it (Niessner et al. 2013 style edge ownership, no hash map). Vertices appear brick
/// by brick in key order, so the mesh is identical for any thread count. Triangles are
/// counter-clockwise seen from the side above the iso value (unless `flip`).
TriangleMesh MeshBricks(const BrickLattice& lattice);

/// Ascending (z, y, x) order of brick keys.
inline bool BrickKeyLess(const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
  if (a.z() != b.z()) return a.z() < b.z();
  if (a.y() != b.y()) return a.y() < b.y();
  return a.x() < b.x();
}

}  // namespace tofnav
