// SPDX-License-Identifier: BSD-3-Clause
// Unit-plane table helpers behind AhatCamera: monotone mask, resampling, bilinear inversion.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <optional>

#include "tofnav/core/image.hpp"

namespace tofnav {

/// A unit-plane point (x, y) (z = 1). A plain struct rather than Eigen, so that the per-entry
/// loops below stay fast in unoptimised test builds.
struct PlanePoint {
  float x = 0.0f;
  float y = 0.0f;
  bool operator==(const PlanePoint&) const = default;
  /// Both coordinates finite (NaN marks an entry without a ray).
  bool finite() const { return std::isfinite(x) && std::isfinite(y); }
};
/// A grid of unit-plane points indexed by table position (column, row).
using UnitPlaneTable = Image<PlanePoint>;
/// 1 = valid, 0 = not; for entries of a table or for its cells.
using Mask = Image<std::uint8_t>;

/// The calibration's table in the plain layout.
UnitPlaneTable ToUnitPlaneTable(const Image<Eigen::Vector2f>& uv2xy);

/// docs/ahat.md section 10 rule: an entry is valid when finite, reached by walking its row (x) and
/// its column (y) outward from the principal point while the coordinate keeps moving away, and not
/// an exact (0, 0) more than a few px from the principal point (zero-filled API failure).
Mask MonotoneTableMask(const UnitPlaneTable& table, const Eigen::Vector2d& principal_point);

/// Drops the entries at which a cell of four valid entries folds over (its bilinear Jacobian
/// determinant, linear over the cell, is not positive at that corner). The monotone walk keeps
/// up to one entry past a fold peak; without this step the surface there would map two positions
/// to one ray, and projection would not be unique.
Mask DropFoldingEntries(const UnitPlaneTable& table, const Mask& entry_valid);

/// Cell mask of an entry mask, (width - 1) x (height - 1): cell (u, v) spans entries u..u+1,
/// v..v+1 and is valid when its four corners are.
Mask CellMask(const Mask& entry_valid);

struct ResampledTable {
  UnitPlaneTable table;  // NaN where not computable
  Mask valid;
};
/// The table at positions (u + shift, v + shift) for every index (u, v). Entry (u, v) is valid
/// when the (up to) four bracketing entries are; its value is a cubic (4 x 4 Lagrange)
/// interpolation when a valid 4 x 4 stencil holds them, else bilinear, so that resampling a smooth
/// table by half a pixel stays at float precision.
ResampledTable ResampleTable(const UnitPlaneTable& table, const Mask& entry_valid, double shift_px);

/// Fractions (a, b) inside cell (u0, v0) (extrapolating outside [0, 1]) where the bilinear
/// interpolation equals target_xy, by Newton from (0.5, 0.5); nullopt when it does not converge.
std::optional<Eigen::Vector2d> SolveInCell(const UnitPlaneTable& table, int u0, int v0,
                                           const Eigen::Vector2d& target_xy);

/// Table position whose bilinear interpolation equals target_xy: Newton iterations from `guess`
/// on the local cell's Jacobian until the step is below 1e-4 px, moving only through cells with
/// cell_valid != 0 (the nearest valid cell when the iterate leaves them). nullopt when it does not
/// converge or the solution lies outside every valid cell.
std::optional<Eigen::Vector2d> InvertBilinear(const UnitPlaneTable& table, const Mask& cell_valid,
                                              const Eigen::Vector2d& target_xy,
                                              const Eigen::Vector2d& guess);

/// Table position where the interpolated (x, y) is (0, 0), refined from the locally monotone
/// entry nearest to it; nullopt when the table has none.
std::optional<Eigen::Vector2d> FindTablePrincipalPoint(const UnitPlaneTable& table);

}  // namespace tofnav
