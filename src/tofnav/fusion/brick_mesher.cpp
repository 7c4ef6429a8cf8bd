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

constexpr int SampleIndex(int x, int y, int z) {
  return x + kBrickSamplesSide * (y + kBrickSamplesSide * z);
}
constexpr int CellIndex(int x, int y, int z) { return x + kBrickSide * (y + kBrickSide * z); }

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

/// Bits set in v (SWAR: the build targets baseline x86-64, which has no popcnt instruction).
constexpr int Popcount(std::uint64_t v) {
  v = v - ((v >> 1) & 0x5555555555555555ull);
  v = (v & 0x3333333333333333ull) + ((v >> 2) & 0x3333333333333333ull);
  v = (v + (v >> 4)) & 0x0F0F0F0F0F0F0F0Full;
  return static_cast<int>((v * 0x0101010101010101ull) >> 56);
}

/// Pass 1: vertices on the brick's own edges and the cells that produce triangles. Samples are
/// packed into 9-bit row masks (bit x of row y + 9 z), so whole rows of edges and cells are
/// classified with a few bit operations and only the crossing ones are visited.
void Classify(const BrickLattice& lattice, std::size_t brick, BrickOutput& out) {
  BrickSamples samples;
  lattice.load(brick, samples);
  constexpr int kRows = kBrickSamplesSide * kBrickSamplesSide;
  std::array<std::uint32_t, kRows> inside{}, valid{};
  std::uint32_t any_inside = 0, any_outside = 0;
  for (int r = 0; r < kRows; ++r) {
    std::uint32_t in = 0, ok = 0;
    for (int x = 0; x < kBrickSamplesSide; ++x) {
      const auto i = static_cast<std::size_t>(r * kBrickSamplesSide + x);
      const float value = samples.value[i];
      const bool usable = samples.valid[i] != 0 && std::isfinite(value);
      ok |= static_cast<std::uint32_t>(usable) << x;
      in |= static_cast<std::uint32_t>(usable && value < 0.0f) << x;
    }
    inside[static_cast<std::size_t>(r)] = in;
    valid[static_cast<std::size_t>(r)] = ok;
    any_inside |= in;
    any_outside |= ok & ~in;
  }
  if (any_inside == 0 || any_outside == 0) return;

  const Eigen::Vector3d first = (kBrickSide * lattice.keys[brick]).cast<double>();
  for (int z = 0; z < kBrickSide; ++z) {
    for (int y = 0; y < kBrickSide; ++y) {
      const auto r = static_cast<std::size_t>(y + kBrickSamplesSide * z);
      const std::size_t next[3] = {r, r + 1, r + kBrickSamplesSide};  // rows of the +x/+y/+z ends
      std::uint32_t crossing[3];
      for (int axis = 0; axis < 3; ++axis) {
        const std::uint32_t shift = axis == 0 ? 1 : 0;
        const std::size_t n = next[axis];
        crossing[axis] =
            (inside[r] ^ (inside[n] >> shift)) & valid[r] & (valid[n] >> shift) & 0xFFu;
      }
      for (std::uint32_t any = crossing[0] | crossing[1] | crossing[2]; any != 0; any &= any - 1) {
        const int x = std::countr_zero(any);
        for (int axis = 0; axis < 3; ++axis) {
          if (((crossing[axis] >> x) & 1u) == 0) continue;
          const int i0 = SampleIndex(x, y, z);
          const double v0 = samples.value[static_cast<std::size_t>(i0)];
          const double v1 = samples.value[static_cast<std::size_t>(
              i0 + kAxisStride[static_cast<std::size_t>(axis)])];
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
    rank += Popcount(out.edge_bits[static_cast<std::size_t>(w)]);
  }
  for (int z = 0; z < kBrickSide; ++z) {
    for (int y = 0; y < kBrickSide; ++y) {
      // Corner c = x | y << 1 | z << 2 of cell x: bits x, x + 1 of these four rows.
      const auto r = static_cast<std::size_t>(y + kBrickSamplesSide * z);
      const std::size_t rows[4] = {r, r + 1, r + kBrickSamplesSide, r + kBrickSamplesSide + 1};
      std::uint32_t ok = 0x1FFu, all = 0x1FFu, some = 0;
      for (const std::size_t row : rows) ok &= valid[row], all &= inside[row], some |= inside[row];
      const std::uint32_t complete = ok & (ok >> 1);
      const std::uint32_t mixed = (some | (some >> 1)) & ~(all & (all >> 1)) & complete & 0xFFu;
      for (std::uint32_t m = mixed; m != 0; m &= m - 1) {
        const int x = std::countr_zero(m);
        std::uint32_t mask = 0;
        for (int k = 0; k < 4; ++k) mask |= ((inside[rows[k]] >> x) & 3u) << (2 * k);
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
                                  Popcount(holder->edge_bits[word] & (bit - 1)));
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
