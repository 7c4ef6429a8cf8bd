// SPDX-License-Identifier: BSD-3-Clause
// Marching-cubes case table (Lorensen & Cline 1987): triangles per corner sign pattern.
#pragma once

#include <array>
#include <cstdint>

namespace tofnav {

/// Corner c of a cell sits at offset (c & 1, (c >> 1) & 1, (c >> 2) & 1) from the cell's first
/// voxel. Edge e runs along axis a = e / 4 from its lower corner; the two other coordinates of
/// that corner are the bits of e % 4, lower axis first. So an edge is (cell voxel + offset, axis),
/// which is how vertices are shared between cells.
constexpr int kMcMaxTriangles = 5;  // the most any case needs

struct McCase {
  std::uint8_t triangle_count = 0;
  /// Edges of each triangle, counter-clockwise seen from the outside (the side with values above
  /// the iso value).
  std::array<std::uint8_t, 3 * kMcMaxTriangles> edges{};
};

/// The triangles of a cell whose corners with bit c set in `inside_mask` (0..255) are inside,
/// i.e. below the iso value. Ambiguous faces are resolved by separating the inside corners, a
/// rule that depends only on the face, so neighbouring cells agree and the surface is closed.
const McCase& MarchingCubesCase(int inside_mask);

/// Lower corner of edge e (0..11), as a corner index.
constexpr int McEdgeLowerCorner(int edge) {
  const int axis = edge / 4;
  const int bits = edge % 4;
  const int lo = bits & 1;         // coordinate of the lower remaining axis
  const int hi = (bits >> 1) & 1;  // coordinate of the higher remaining axis
  if (axis == 0) return (lo << 1) | (hi << 2);
  if (axis == 1) return lo | (hi << 2);
  return lo | (hi << 1);
}
/// Upper corner of edge e: the lower corner moved by one along the edge's axis.
constexpr int McEdgeUpperCorner(int edge) { return McEdgeLowerCorner(edge) | (1 << (edge / 4)); }

}  // namespace tofnav
