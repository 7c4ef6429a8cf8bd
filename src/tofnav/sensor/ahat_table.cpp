// SPDX-License-Identifier: BSD-3-Clause
// Unit-plane table helpers behind AhatCamera: bilinear inversion and the principal point.
#include "tofnav/sensor/ahat_table.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace tofnav {
namespace {

constexpr int kMaxNewtonIterations = 20;
constexpr double kConvergedStepPx = 1e-4;  // brief: stop once the step is below 1e-4 px
constexpr double kMaxStepPx = 8.0;         // damping: far jumps only leave the local patch
constexpr double kCellSlackPx = 1e-6;      // a converged point this close to a valid cell is in it
constexpr double kMinDeterminant = 1e-14;  // unit-plane^2 per px^2; the centre has ~1.5e-5
constexpr int kSearchRadiusCells = 2;      // fallback search around a guess Newton could not use

/// One table cell as x(a, b) = x0 + xa a + (xb + xab a) b, and the same for y (scalars: this is
/// the inner loop of every projection, and it must stay fast unoptimised too).
struct Cell {
  Cell(const UnitPlaneTable& table, int u0, int v0) {
    const PlanePoint& q00 = table(u0, v0);
    const PlanePoint& q10 = table(u0 + 1, v0);
    const PlanePoint& q01 = table(u0, v0 + 1);
    const PlanePoint& q11 = table(u0 + 1, v0 + 1);
    x0 = q00.x;
    xa = double{q10.x} - x0;
    xb = double{q01.x} - x0;
    xab = double{q11.x} - q10.x - q01.x + x0;
    y0 = q00.y;
    ya = double{q10.y} - y0;
    yb = double{q01.y} - y0;
    yab = double{q11.y} - q10.y - q01.y + y0;
  }
  double x0, xa, xb, xab, y0, ya, yb, yab;
};

struct CellOffset {  // fractions (a, b) in a cell, or a Newton step in them
  double a, b;
};

/// Newton step at (a, b) towards (tx, ty) with the cell's local Jacobian; nullopt if singular.
std::optional<CellOffset> NewtonStep(const Cell& c, double a, double b, double tx, double ty) {
  const double rx = tx - (c.x0 + c.xa * a + (c.xb + c.xab * a) * b);
  const double ry = ty - (c.y0 + c.ya * a + (c.yb + c.yab * a) * b);
  const double j00 = c.xa + c.xab * b;
  const double j01 = c.xb + c.xab * a;
  const double j10 = c.ya + c.yab * b;
  const double j11 = c.yb + c.yab * a;
  const double det = j00 * j11 - j01 * j10;
  if (!(std::abs(det) > kMinDeterminant)) return std::nullopt;
  return CellOffset{(j11 * rx - j01 * ry) / det, (j00 * ry - j10 * rx) / det};
}

int ClampCell(double position, int cells) {
  const double floored = std::floor(position);
  if (!(floored >= 0.0)) return 0;  // also catches NaN
  return floored >= cells - 1 ? cells - 1 : static_cast<int>(floored);
}

/// The valid cell nearest to position (pu, pv) among the 3 x 3 around the one containing it.
std::optional<std::pair<int, int>> NearestValidCell(const Mask& cells, double pu, double pv) {
  const int cu = ClampCell(pu, cells.width());
  const int cv = ClampCell(pv, cells.height());
  if (cells(cu, cv) != 0 && pu >= cu && pu <= cu + 1 && pv >= cv && pv <= cv + 1) {
    return std::pair{cu, cv};
  }
  std::optional<std::pair<int, int>> best;
  double best_distance = std::numeric_limits<double>::infinity();
  for (int v = cv - 1; v <= cv + 1; ++v) {
    for (int u = cu - 1; u <= cu + 1; ++u) {
      if (!cells.Contains(u, v) || cells(u, v) == 0) continue;
      const double du = std::max({0.0, u - pu, pu - (u + 1)});
      const double dv = std::max({0.0, v - pv, pv - (v + 1)});
      if (du * du + dv * dv < best_distance) {
        best_distance = du * du + dv * dv;
        best = std::pair{u, v};
      }
    }
  }
  return best;
}

/// (a, b) in the cell (possibly outside [0, 1]) where it interpolates (tx, ty), by Newton from
/// the cell centre; nullopt when it does not converge.
std::optional<CellOffset> SolveCell(const Cell& cell, double tx, double ty) {
  double a = 0.5;
  double b = 0.5;
  for (int iteration = 0; iteration < kMaxNewtonIterations; ++iteration) {
    const std::optional<CellOffset> step = NewtonStep(cell, a, b, tx, ty);
    if (!step) return std::nullopt;
    a += step->a;
    b += step->b;
    if (std::abs(step->a) + std::abs(step->b) < kConvergedStepPx) return CellOffset{a, b};
  }
  return std::nullopt;
}

/// Newton from (pu, pv), moving into the valid cell that contains (or is nearest to) each
/// iterate. nullopt when it stalls or converges outside every valid cell.
std::optional<Eigen::Vector2d> WalkNewton(const UnitPlaneTable& table, const Mask& cell_valid,
                                          double tx, double ty, double pu, double pv) {
  std::optional<std::pair<int, int>> index = NearestValidCell(cell_valid, pu, pv);
  if (!index) return std::nullopt;
  auto [u0, v0] = *index;
  Cell cell(table, u0, v0);
  for (int iteration = 0; iteration < kMaxNewtonIterations; ++iteration) {
    const std::optional<CellOffset> step = NewtonStep(cell, pu - u0, pv - v0, tx, ty);
    if (!step) return std::nullopt;
    const double step_px = std::sqrt(step->a * step->a + step->b * step->b);
    const double scale = step_px > kMaxStepPx ? kMaxStepPx / step_px : 1.0;
    pu += scale * step->a;
    pv += scale * step->b;
    if (!std::isfinite(pu) || !std::isfinite(pv)) return std::nullopt;
    index = NearestValidCell(cell_valid, pu, pv);  // else keep extrapolating the last cell
    if (index && (index->first != u0 || index->second != v0)) {
      std::tie(u0, v0) = *index;
      cell = Cell(table, u0, v0);
    }
    if (step_px < kConvergedStepPx) {
      if (pu < u0 - kCellSlackPx || pu > u0 + 1 + kCellSlackPx || pv < v0 - kCellSlackPx ||
          pv > v0 + 1 + kCellSlackPx) {
        return std::nullopt;  // converged outside every valid cell
      }
      return Eigen::Vector2d(std::clamp(pu, double(u0), u0 + 1.0),
                             std::clamp(pv, double(v0), v0 + 1.0));
    }
  }
  return std::nullopt;
}

}  // namespace

UnitPlaneTable ToUnitPlaneTable(const Image<Eigen::Vector2f>& uv2xy) {
  UnitPlaneTable table(uv2xy.width(), uv2xy.height());
  for (int v = 0; v < uv2xy.height(); ++v) {
    for (int u = 0; u < uv2xy.width(); ++u) {
      const Eigen::Vector2f& xy = uv2xy(u, v);
      table(u, v) = {xy.x(), xy.y()};
    }
  }
  return table;
}

std::optional<Eigen::Vector2d> SolveInCell(const UnitPlaneTable& table, int u0, int v0,
                                           const Eigen::Vector2d& target_xy) {
  const std::optional<CellOffset> ab = SolveCell(Cell(table, u0, v0), target_xy.x(), target_xy.y());
  if (!ab) return std::nullopt;
  return Eigen::Vector2d(ab->a, ab->b);
}

std::optional<Eigen::Vector2d> InvertBilinear(const UnitPlaneTable& table, const Mask& cell_valid,
                                              const Eigen::Vector2d& target_xy,
                                              const Eigen::Vector2d& guess) {
  const double tx = target_xy.x();
  const double ty = target_xy.y();
  const double pu = guess.x();
  const double pv = guess.y();
  if (table.width() < 2 || table.height() < 2 || cell_valid.width() != table.width() - 1 ||
      cell_valid.height() != table.height() - 1 || !std::isfinite(tx) || !std::isfinite(ty) ||
      !std::isfinite(pu) || !std::isfinite(pv)) {
    return std::nullopt;
  }
  if (const std::optional<Eigen::Vector2d> walked = WalkNewton(table, cell_valid, tx, ty, pu, pv)) {
    return walked;
  }
  // Next to the fold the cells are distorted enough to send Newton astray: try every valid
  // cell near the guess directly and keep the nearest one containing a solution.
  const int cu = ClampCell(pu, cell_valid.width());
  const int cv = ClampCell(pv, cell_valid.height());
  std::optional<Eigen::Vector2d> best;
  double best_distance = std::numeric_limits<double>::infinity();
  for (int v = cv - kSearchRadiusCells; v <= cv + kSearchRadiusCells; ++v) {
    for (int u = cu - kSearchRadiusCells; u <= cu + kSearchRadiusCells; ++u) {
      if (!cell_valid.Contains(u, v) || cell_valid(u, v) == 0) continue;
      const std::optional<CellOffset> ab = SolveCell(Cell(table, u, v), tx, ty);
      if (!ab || ab->a < -kCellSlackPx || ab->a > 1 + kCellSlackPx || ab->b < -kCellSlackPx ||
          ab->b > 1 + kCellSlackPx) {
        continue;
      }
      const double su = u + std::clamp(ab->a, 0.0, 1.0);
      const double sv = v + std::clamp(ab->b, 0.0, 1.0);
      const double distance = (su - pu) * (su - pu) + (sv - pv) * (sv - pv);
      if (distance < best_distance) {
        best_distance = distance;
        best = Eigen::Vector2d(su, sv);
      }
    }
  }
  return best;
}

std::optional<Eigen::Vector2d> FindTablePrincipalPoint(const UnitPlaneTable& table) {
  Mask finite(table.width(), table.height());
  for (int v = 0; v < table.height(); ++v) {
    for (int u = 0; u < table.width(); ++u) finite(u, v) = table(u, v).finite() ? 1 : 0;
  }
  // The entry nearest to (0, 0) among those where x grows with u and y with v through it:
  // zero-filled failures and folded corners fail that test.
  double best = std::numeric_limits<double>::infinity();
  std::optional<Eigen::Vector2d> start;
  for (int v = 1; v + 1 < table.height(); ++v) {
    for (int u = 1; u + 1 < table.width(); ++u) {
      const PlanePoint& xy = table(u, v);
      const double distance = double{xy.x} * xy.x + double{xy.y} * xy.y;
      if (!(distance < best) || !finite(u - 1, v) || !finite(u + 1, v) || !finite(u, v - 1) ||
          !finite(u, v + 1) || !(table(u - 1, v).x < xy.x && xy.x < table(u + 1, v).x) ||
          !(table(u, v - 1).y < xy.y && xy.y < table(u, v + 1).y)) {
        continue;  // NaN distances fail the first test
      }
      best = distance;
      start = Eigen::Vector2d(u, v);
    }
  }
  if (!start) return std::nullopt;
  return InvertBilinear(table, CellMask(finite), Eigen::Vector2d::Zero(), *start);
}

}  // namespace tofnav
