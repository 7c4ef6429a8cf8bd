// SPDX-License-Identifier: BSD-3-Clause
// Internal: marching cubes over sparse 8^3 bricks with edge-owned shared vertices.
#include "tofnav/fusion/brick_mesher.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/fusion/marching_cubes_tables.hpp"

namespace tofnav {
namespace {

constexpr int kBrickCells = kBrickSide * kBrickSide * kBrickSide;
constexpr int kOwnedEdges = 3 * kBrickCells;  // +x, +y, +z edge of each own lattice point
constexpr std::array<int, 3> kAxisStride = {1, kBrickSamplesSide,
                                            kBrickSamplesSide* kBrickSamplesSide};
constexpr std::uint8_t kInvalid = 0, kOutside = 1, kInside = 2;

constexpr int SampleIndex(int x, int y, int z) {
  return x + kBrickSamplesSide * (y + kBrickSamplesSide * z);
}
constexpr int CellIndex(int x, int y, int z) { return x + kBrickSide * (y + kBrickSide * z); }

constexpr std::array<int, 8> CornerOffsets() {
  std::array<int, 8> offsets{};
  for (int c = 0; c < 8; ++c) offsets[c] = SampleIndex(c & 1, (c >> 1) & 1, (c >> 2) & 1);
  return offsets;
}
constexpr std::array<int, 8> kCornerOffset = CornerOffsets();

constexpr int kEdgeWords = kOwnedEdges / 64;

/// Owned edge slot 3 * cell + axis, in the order Classify creates vertices.
constexpr int EdgeSlot(int cell, int axis) { return 3 * cell + axis; }

struct BrickOutput {
  Points3d vertices;  // on owned edges, in slot order
  // Which owned edges hold a vertex, and how many vertices precede each word: a vertex's local
  // index is the rank of its slot (a few bytes per brick instead of a 6 KB table).
  std::array<std::uint64_t, kEdgeWords> edge_bits{};
  std::array<std::uint16_t, kEdgeWords> edge_rank{};
  std::vector<std::pair<std::uint16_t, std::uint8_t>> cells;  // (cell, case) with triangles
  std::vector<Eigen::Vector3i> triangles;                     // global vertex ids
  std::int64_t first_vertex = 0;
};

/// Pass 1: vertices on the brick's own edges and the cells that produce triangles.
void Classify(const BrickLattice& lattice, std::size_t brick, BrickOutput& out) {
  BrickSamples samples;
  lattice.load(brick, samples);
  std::array<std::uint8_t, kBrickSamples> flag;
  bool any_inside = false, any_outside = false;
  for (int i = 0; i < kBrickSamples; ++i) {
    const float value = samples.value[static_cast<std::size_t>(i)];
    const bool valid = samples.valid[static_cast<std::size_t>(i)] != 0 && std::isfinite(value);
    flag[static_cast<std::size_t>(i)] = !valid ? kInvalid : value < 0.0f ? kInside : kOutside;
    any_inside |= valid && value < 0.0f;
    any_outside |= valid && value >= 0.0f;
  }
  if (!any_inside || !any_outside) return;

  const Eigen::Vector3d first = (kBrickSide * lattice.keys[brick]).cast<double>();
  for (int z = 0; z < kBrickSide; ++z) {
    for (int y = 0; y < kBrickSide; ++y) {
      for (int x = 0; x < kBrickSide; ++x) {
        const int i0 = SampleIndex(x, y, z);
        const std::uint8_t f0 = flag[static_cast<std::size_t>(i0)];
        if (f0 == kInvalid) continue;
        for (int axis = 0; axis < 3; ++axis) {
          const int i1 = i0 + kAxisStride[static_cast<std::size_t>(axis)];
          const std::uint8_t f1 = flag[static_cast<std::size_t>(i1)];
          if (f1 == kInvalid || f1 == f0) continue;
          const double v0 = samples.value[static_cast<std::size_t>(i0)];
          const double v1 = samples.value[static_cast<std::size_t>(i1)];
          Eigen::Vector3d point = first + Eigen::Vector3d(x, y, z);
          point[axis] += v0 / (v0 - v1);  // where the linear interpolant crosses zero
          const int slot = EdgeSlot(CellIndex(x, y, z), axis);
          out.edge_bits[static_cast<std::size_t>(slot / 64)] |= std::uint64_t{1} << (slot % 64);
          out.vertices.push_back(lattice.linear * point + lattice.offset);
        }
      }
    }
  }
  int rank = 0;
  for (int w = 0; w < kEdgeWords; ++w) {
    out.edge_rank[static_cast<std::size_t>(w)] = static_cast<std::uint16_t>(rank);
    rank += std::popcount(out.edge_bits[static_cast<std::size_t>(w)]);
  }
  for (int z = 0; z < kBrickSide; ++z) {
    for (int y = 0; y < kBrickSide; ++y) {
      for (int x = 0; x < kBrickSide; ++x) {
        const int base = SampleIndex(x, y, z);
        int mask = 0;
        bool valid = true;
        for (int c = 0; c < 8 && valid; ++c) {
          const std::uint8_t f =
              flag[static_cast<std::size_t>(base + kCornerOffset[static_cast<std::size_t>(c)])];
          valid = f != kInvalid;
          if (f == kInside) mask |= 1 << c;
        }
        if (!valid || mask == 0 || mask == 255) continue;
        out.cells.emplace_back(static_cast<std::uint16_t>(CellIndex(x, y, z)),
                               static_cast<std::uint8_t>(mask));
      }
    }
  }
}

/// Pass 2: triangles of the brick's cells with global vertex ids; an edge on the brick's far
/// faces belongs to the neighbour brick that owns its lower lattice point.
void Triangulate(const BrickLattice& lattice, std::vector<BrickOutput>& outputs,
                 std::size_t brick) {
  BrickOutput& out = outputs[brick];
  std::array<std::int64_t, 8> owner{};  // by offset bits x | y << 1 | z << 2; -2 = not looked up
  owner.fill(-2);
  owner[0] = static_cast<std::int64_t>(brick);
  const Eigen::Vector3i& key = lattice.keys[brick];
  out.triangles.reserve(2 * out.cells.size());
  for (const auto& [cell, mask] : out.cells) {
    const int cx = cell % kBrickSide, cy = (cell / kBrickSide) % kBrickSide,
              cz = cell / (kBrickSide * kBrickSide);
    const McCase& triangles = MarchingCubesCase(mask);
    for (int t = 0; t < triangles.triangle_count; ++t) {
      int ids[3];
      for (int k = 0; k < 3; ++k) {
        const int edge = triangles.edges[static_cast<std::size_t>(3 * t + k)];
        const int corner = McEdgeLowerCorner(edge);
        // The edge's lower lattice point; on the far faces it belongs to a neighbour brick.
        int x = cx + (corner & 1), y = cy + ((corner >> 1) & 1), z = cz + ((corner >> 2) & 1);
        const int bits =
            (x >= kBrickSide ? 1 : 0) | (y >= kBrickSide ? 2 : 0) | (z >= kBrickSide ? 4 : 0);
        std::int64_t& o = owner[static_cast<std::size_t>(bits)];
        if (o == -2) {
          const Eigen::Vector3i neighbour =
              key + Eigen::Vector3i(bits & 1, (bits >> 1) & 1, bits >> 2);
          const auto it =
              std::lower_bound(lattice.keys.begin(), lattice.keys.end(), neighbour, BrickKeyLess);
          o = it != lattice.keys.end() && *it == neighbour ? it - lattice.keys.begin() : -1;
        }
        x -= (bits & 1) * kBrickSide, y -= ((bits >> 1) & 1) * kBrickSide,
            z -= (bits >> 2) * kBrickSide;
        const int slot = EdgeSlot(CellIndex(x, y, z), edge / 4);
        const auto word = static_cast<std::size_t>(slot / 64);
        const std::uint64_t bit = std::uint64_t{1} << (slot % 64);
        const BrickOutput* holder = o >= 0 ? &outputs[static_cast<std::size_t>(o)] : nullptr;
        if (holder == nullptr || (holder->edge_bits[word] & bit) == 0) {
          throw std::logic_error("MeshBricks: a brick owning a crossed edge is missing");
        }
        ids[k] = static_cast<int>(holder->first_vertex + holder->edge_rank[word] +
                                  std::popcount(holder->edge_bits[word] & (bit - 1)));
      }
      if (lattice.flip) std::swap(ids[1], ids[2]);
      out.triangles.emplace_back(ids[0], ids[1], ids[2]);
    }
  }
}

}  // namespace

TriangleMesh MeshBricks(const BrickLattice& lattice) {
  const std::size_t n = lattice.keys.size();
  std::vector<BrickOutput> outputs(n);
  ParallelFor(0, static_cast<std::int64_t>(n), [&](std::int64_t i) {
    Classify(lattice, static_cast<std::size_t>(i), outputs[static_cast<std::size_t>(i)]);
  });
  std::int64_t vertex_count = 0;
  for (BrickOutput& out : outputs) {
    out.first_vertex = vertex_count;
    vertex_count += static_cast<std::int64_t>(out.vertices.size());
  }
  if (vertex_count > std::numeric_limits<int>::max()) {
    throw std::length_error("MeshBricks: more vertices than an int index holds");
  }
  ParallelFor(0, static_cast<std::int64_t>(n),
              [&](std::int64_t i) { Triangulate(lattice, outputs, static_cast<std::size_t>(i)); });

  // Keep only vertices that a triangle uses (an edge can cross with no complete cell beside it).
  std::vector<int> remap(static_cast<std::size_t>(vertex_count), -1);
  std::size_t triangle_count = 0;
  for (const BrickOutput& out : outputs) {
    triangle_count += out.triangles.size();
    for (const Eigen::Vector3i& t : out.triangles) {
      for (int k = 0; k < 3; ++k) remap[static_cast<std::size_t>(t[k])] = 0;
    }
  }
  TriangleMesh mesh;
  for (const BrickOutput& out : outputs) {
    for (std::size_t v = 0; v < out.vertices.size(); ++v) {
      int& id = remap[static_cast<std::size_t>(out.first_vertex) + v];
      if (id < 0) continue;
      id = static_cast<int>(mesh.vertices.size());
      mesh.vertices.push_back(out.vertices[v]);
    }
  }
  mesh.triangles.reserve(triangle_count);
  for (const BrickOutput& out : outputs) {
    for (const Eigen::Vector3i& t : out.triangles) {
      mesh.triangles.emplace_back(remap[static_cast<std::size_t>(t[0])],
                                  remap[static_cast<std::size_t>(t[1])],
                                  remap[static_cast<std::size_t>(t[2])]);
    }
  }
  return mesh;
}

}  // namespace tofnav
