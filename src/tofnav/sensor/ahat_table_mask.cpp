// SPDX-License-Identifier: BSD-3-Clause
// Validity masks of a unit-plane table: the monotone region (docs/ahat.md 10), folds, cells.
#include <algorithm>
#include <cmath>

#include "tofnav/sensor/ahat_table.hpp"

namespace tofnav {
namespace {

constexpr double kZeroFillMinRadiusPx = 2.0;  // exact (0, 0) farther than this is a failed call

/// Walks entries first, first + step, ... while `coordinate` keeps growing in `step`'s sense;
/// calls clear() on every entry from the first that breaks the rule to the end of the line.
template <typename Coordinate, typename Clear>
void WalkOutward(int first, int step, int end, Coordinate coordinate, Clear clear) {
  float last = coordinate(first);
  bool ok = std::isfinite(last);
  for (int i = first + step; i != end; i += step) {
    const float value = coordinate(i);
    ok = ok && std::isfinite(value) && (step > 0 ? value > last : value < last);
    if (ok) last = value;
    if (!ok) clear(i);
  }
}

}  // namespace

Mask MonotoneTableMask(const UnitPlaneTable& table, const Eigen::Vector2d& principal_point) {
  const int width = table.width();
  const int height = table.height();
  Mask mask(width, height);
  if (width == 0 || height == 0) return mask;
  const double zero_fill_radius2 = kZeroFillMinRadiusPx * kZeroFillMinRadiusPx;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const PlanePoint& xy = table(u, v);
      const double du = u - principal_point.x();
      const double dv = v - principal_point.y();
      const bool zero_fill = xy.x == 0.0f && xy.y == 0.0f && du * du + dv * dv > zero_fill_radius2;
      mask(u, v) = (xy.finite() && !zero_fill) ? 1 : 0;
    }
  }
  const auto nearest_index = [](double position, int entries) {
    return std::clamp(static_cast<int>(std::lround(position)), 0, entries - 1);
  };
  const int centre_u = nearest_index(principal_point.x(), width);
  const int centre_v = nearest_index(principal_point.y(), height);
  for (int v = 0; v < height; ++v) {  // rows: x grows to the right of the centre column
    const auto x = [&](int u) { return table(u, v).x; };
    const auto clear = [&](int u) { mask(u, v) = 0; };
    if (!std::isfinite(x(centre_u))) clear(centre_u);
    WalkOutward(centre_u, +1, width, x, clear);
    WalkOutward(centre_u, -1, -1, x, clear);
  }
  for (int u = 0; u < width; ++u) {  // columns: y grows below the centre row
    const auto y = [&](int v) { return table(u, v).y; };
    const auto clear = [&](int v) { mask(u, v) = 0; };
    if (!std::isfinite(y(centre_v))) clear(centre_v);
    WalkOutward(centre_v, +1, height, y, clear);
    WalkOutward(centre_v, -1, -1, y, clear);
  }
  return mask;
}

Mask DropFoldingEntries(const UnitPlaneTable& table, const Mask& entry_valid) {
  Mask out = entry_valid;
  const Mask cells = CellMask(entry_valid);
  for (int v = 0; v < cells.height(); ++v) {
    for (int u = 0; u < cells.width(); ++u) {
      if (cells(u, v) == 0) continue;
      // The bilinear cell's Jacobian determinant is linear in (a, b): its corners bound it.
      const PlanePoint& q00 = table(u, v);
      const PlanePoint& q10 = table(u + 1, v);
      const PlanePoint& q01 = table(u, v + 1);
      const PlanePoint& q11 = table(u + 1, v + 1);
      // d/da along the rows b = 0, 1 and d/db along the columns a = 0, 1, as (x, y).
      const double along_u[2][2] = {{double{q10.x} - q00.x, double{q10.y} - q00.y},
                                    {double{q11.x} - q01.x, double{q11.y} - q01.y}};
      const double along_v[2][2] = {{double{q01.x} - q00.x, double{q01.y} - q00.y},
                                    {double{q11.x} - q10.x, double{q11.y} - q10.y}};
      for (int corner = 0; corner < 4; ++corner) {
        const int a = corner % 2;
        const int b = corner / 2;
        const double det = along_u[b][0] * along_v[a][1] - along_u[b][1] * along_v[a][0];
        if (!(det > 0.0)) out(u + a, v + b) = 0;  // x right, y down: positive orientation
      }
    }
  }
  return out;
}

Mask CellMask(const Mask& entry_valid) {
  const int width = std::max(entry_valid.width() - 1, 0);
  const int height = std::max(entry_valid.height() - 1, 0);
  Mask cells(width, height);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      cells(u, v) = (entry_valid(u, v) != 0 && entry_valid(u + 1, v) != 0 &&
                     entry_valid(u, v + 1) != 0 && entry_valid(u + 1, v + 1) != 0)
                        ? 1
                        : 0;
    }
  }
  return cells;
}

}  // namespace tofnav
