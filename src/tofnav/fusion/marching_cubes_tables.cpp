// SPDX-License-Identifier: BSD-3-Clause
// Marching-cubes case table, derived at compile time from the cube's faces (no literal table).
#include "tofnav/fusion/marching_cubes_tables.hpp"

#include <stdexcept>

namespace tofnav {
namespace {

// The 256 cases are built the way the surface is defined rather than typed in: on each face of
// the cell, the crossing edges (one corner inside, one outside) are joined into segments that
// separate inside from outside corners; the segments of the six faces chain into closed loops
// around the cell, and each loop is split into triangles without a diagonal across a cube face.
// A face with four crossings (inside corners on a diagonal) separates the inside corners. The
// face decision depends only on the face's corners, so both cells sharing a face make the same
// one, and the mesh has no cracks and no edge shared by more than two triangles.

struct Vec {  // doubled coordinates, so edge midpoints are integers
  int x = 0, y = 0, z = 0;
};
constexpr Vec operator-(const Vec& a, const Vec& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
constexpr Vec operator+(const Vec& a, const Vec& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
constexpr Vec Scale(const Vec& a, int s) { return {a.x * s, a.y * s, a.z * s}; }
constexpr int Dot(const Vec& a, const Vec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec Cross(const Vec& a, const Vec& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
constexpr Vec CornerPosition(int c) {
  return {2 * (c & 1), 2 * ((c >> 1) & 1), 2 * ((c >> 2) & 1)};
}
constexpr Vec EdgeMidpoint(int e) {
  const Vec a = CornerPosition(McEdgeLowerCorner(e));
  const Vec b = CornerPosition(McEdgeUpperCorner(e));
  return {(a.x + b.x) / 2, (a.y + b.y) / 2, (a.z + b.z) / 2};
}
constexpr bool Inside(int mask, int corner) { return ((mask >> corner) & 1) != 0; }
constexpr bool Crosses(int mask, int e) {
  return Inside(mask, McEdgeLowerCorner(e)) != Inside(mask, McEdgeUpperCorner(e));
}

/// Orients segment {a, b} on a face with outward normal `normal` so that (b - a) x normal points
/// towards `inside_direction`, and records it as a -> b.
constexpr void Link(std::array<int, 12>& next, int a, int b, const Vec& normal,
                    const Vec& inside_direction) {
  const Vec along = EdgeMidpoint(b) - EdgeMidpoint(a);
  const int side = Dot(Cross(along, normal), inside_direction);
  if (side == 0) throw std::logic_error("marching cubes: degenerate face segment");
  if (side < 0) {
    const int t = a;
    a = b;
    b = t;
  }
  if (next[static_cast<std::size_t>(a)] != -1) throw std::logic_error("marching cubes: fork");
  next[static_cast<std::size_t>(a)] = b;
}

constexpr void LinkFace(int mask, int axis, int side, std::array<int, 12>& next) {
  Vec normal;
  (axis == 0 ? normal.x : axis == 1 ? normal.y : normal.z) = side == 1 ? 1 : -1;
  int crossing[4] = {0, 0, 0, 0};
  int n = 0;
  for (int e = 0; e < 12; ++e) {
    if (e / 4 == axis || ((McEdgeLowerCorner(e) >> axis) & 1) != side) continue;
    if (Crosses(mask, e)) crossing[n++] = e;
  }
  if (n == 2) {
    Vec in_sum, out_sum;
    int in_count = 0, out_count = 0;
    for (int c = 0; c < 8; ++c) {
      if (((c >> axis) & 1) != side) continue;
      if (Inside(mask, c)) {
        in_sum = in_sum + CornerPosition(c);
        ++in_count;
      } else {
        out_sum = out_sum + CornerPosition(c);
        ++out_count;
      }
    }
    Link(next, crossing[0], crossing[1], normal,
         Scale(in_sum, out_count) - Scale(out_sum, in_count));
  } else if (n == 4) {
    for (int c = 0; c < 8; ++c) {  // cut off each inside corner with its two crossing edges
      if (((c >> axis) & 1) != side || !Inside(mask, c)) continue;
      int ends[2] = {0, 0};
      int m = 0;
      for (int e : crossing) {
        if (McEdgeLowerCorner(e) == c || McEdgeUpperCorner(e) == c) ends[m++] = e;
      }
      const Vec direction =
          Scale(CornerPosition(c), 2) - (EdgeMidpoint(ends[0]) + EdgeMidpoint(ends[1]));
      Link(next, ends[0], ends[1], normal, direction);
    }
  }
}

constexpr bool OnFace(int edge, int axis, int side) {
  return edge / 4 != axis && ((McEdgeLowerCorner(edge) >> axis) & 1) == side;
}
constexpr bool ShareFace(int a, int b) {
  for (int face = 0; face < 6; ++face) {
    if (OnFace(a, face / 2, face % 2) && OnFace(b, face / 2, face % 2)) return true;
  }
  return false;
}

struct Loop {
  int edges[12] = {};
  int length = 0;
};

/// Triangulates loop vertices i..j (joined by a side or an accepted diagonal) into `result`.
/// A diagonal must not join two vertices on one cube face: the neighbour sharing that face could
/// use the same pair, and three triangles would meet at an edge. Returns false when impossible.
constexpr bool Triangulate(const Loop& loop, int i, int j, McCase& result) {
  if (j - i < 2) return true;
  const auto allowed = [&](int a, int b) {
    return b - a == 1 || !ShareFace(loop.edges[a], loop.edges[b]);
  };
  for (int k = i + 1; k < j; ++k) {
    if (!allowed(i, k) || !allowed(k, j)) continue;
    McCase attempt = result;
    if (attempt.triangle_count == kMcMaxTriangles) throw std::logic_error("too many triangles");
    const std::size_t base = 3u * attempt.triangle_count++;
    attempt.edges[base] = static_cast<std::uint8_t>(loop.edges[i]);
    attempt.edges[base + 1] = static_cast<std::uint8_t>(loop.edges[k]);
    attempt.edges[base + 2] = static_cast<std::uint8_t>(loop.edges[j]);
    if (Triangulate(loop, i, k, attempt) && Triangulate(loop, k, j, attempt)) {
      result = attempt;
      return true;
    }
  }
  return false;
}

constexpr McCase BuildCase(int mask) {
  std::array<int, 12> next{};
  for (int& n : next) n = -1;
  for (int face = 0; face < 6; ++face) LinkFace(mask, face / 2, face % 2, next);
  McCase result;
  std::array<bool, 12> visited{};
  for (int start = 0; start < 12; ++start) {
    if (next[static_cast<std::size_t>(start)] == -1 || visited[static_cast<std::size_t>(start)]) {
      continue;
    }
    Loop loop;
    for (int e = start; !visited[static_cast<std::size_t>(e)];
         e = next[static_cast<std::size_t>(e)]) {
      visited[static_cast<std::size_t>(e)] = true;
      loop.edges[loop.length++] = e;
      if (next[static_cast<std::size_t>(e)] == -1) throw std::logic_error("open loop");
    }
    if (!Triangulate(loop, 0, loop.length - 1, result)) {
      throw std::logic_error("marching cubes: no triangulation without face diagonals");
    }
  }
  return result;
}

constexpr std::array<McCase, 256> BuildTable() {
  std::array<McCase, 256> table{};
  for (int mask = 0; mask < 256; ++mask) table[static_cast<std::size_t>(mask)] = BuildCase(mask);
  return table;
}

constexpr std::array<McCase, 256> kCases = BuildTable();

}  // namespace

const McCase& MarchingCubesCase(int inside_mask) {
  return kCases[static_cast<std::size_t>(inside_mask & 255)];
}

}  // namespace tofnav
