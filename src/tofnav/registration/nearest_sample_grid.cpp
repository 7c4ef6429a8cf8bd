// SPDX-License-Identifier: BSD-3-Clause
// NearestSampleGrid: splat every sample into the cells within its reach.
#include "tofnav/registration/nearest_sample_grid.hpp"

#include <cmath>
#include <limits>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr std::int64_t kMaxCells = std::int64_t{1} << 26;  // 256 MB of indices at most

}  // namespace

NearestSampleGrid::NearestSampleGrid(const Points3d& samples, double cell_mm, double reach_mm)
    : inverse_cell_(1.0 / cell_mm) {
  Require(cell_mm > 0.0 && reach_mm >= 0.0, "NearestSampleGrid: cell_mm > 0, reach_mm >= 0");
  Require(!samples.empty() && samples.size() < std::numeric_limits<std::int32_t>::max(),
          "NearestSampleGrid: needs 1 .. 2^31 - 1 samples");
  const double margin_mm = reach_mm + 2.0 * cell_mm;  // every splat stays inside the grid
  Eigen::Vector3d low = samples.front(), high = samples.front();
  for (const Eigen::Vector3d& p : samples) low = low.cwiseMin(p), high = high.cwiseMax(p);
  const Eigen::Vector3d origin = low - Eigen::Vector3d::Constant(margin_mm);
  const Eigen::Vector3d extent = (high - low).array() + 2.0 * margin_mm;
  const Eigen::Vector3d cells = (extent / cell_mm).array().ceil();
  Require(cells.allFinite() && cells.prod() <= static_cast<double>(kMaxCells),
          "NearestSampleGrid: the samples span too large a box for the cell size");
  for (int k = 0; k < 3; ++k) {
    origin_[k] = origin(k);
    size_[k] = static_cast<std::int64_t>(cells(k));
    size_d_[k] = cells(k);
  }
  const std::int64_t total = size_[0] * size_[1] * size_[2];
  cells_.assign(static_cast<std::size_t>(total), -1);
  std::vector<double> best_sq(cells_.size(), std::numeric_limits<double>::infinity());
  const double half_diagonal_mm = 0.5 * std::sqrt(3.0) * cell_mm;
  const double limit_sq = (reach_mm + half_diagonal_mm) * (reach_mm + half_diagonal_mm);
  const auto span = static_cast<std::int64_t>(std::ceil((reach_mm + half_diagonal_mm) / cell_mm));
  const double limit_cells_sq = limit_sq / (cell_mm * cell_mm);
  // Plain scalars in the splat loop: it runs span^3 times per sample (unoptimised builds too).
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Eigen::Vector3d local = (samples[i] - origin) / cell_mm;  // in cells
    const double lx = local.x(), ly = local.y(), lz = local.z();
    const auto cy = static_cast<std::int64_t>(std::floor(ly));
    const auto cz = static_cast<std::int64_t>(std::floor(lz));
    for (std::int64_t z = cz - span; z <= cz + span; ++z) {
      const double dz = static_cast<double>(z) + 0.5 - lz;
      for (std::int64_t y = cy - span; y <= cy + span; ++y) {
        const double dy = static_cast<double>(y) + 0.5 - ly;
        const double dyz_sq = dy * dy + dz * dz;
        if (dyz_sq > limit_cells_sq) continue;
        const std::int64_t row = (z * size_[1] + y) * size_[0];
        // Only the cells of this row inside the sphere: |x + 0.5 - local.x| <= half_width.
        const double half_width = std::sqrt(limit_cells_sq - dyz_sq);
        const auto x_first = static_cast<std::int64_t>(std::ceil(lx - 0.5 - half_width));
        const auto x_last = static_cast<std::int64_t>(std::floor(lx - 0.5 + half_width));
        for (std::int64_t x = x_first; x <= x_last; ++x) {
          const double dx = static_cast<double>(x) + 0.5 - lx;
          const double d_sq = dx * dx + dyz_sq;
          const auto at = static_cast<std::size_t>(row + x);
          if (d_sq >= best_sq[at]) continue;  // equal: the lower index stays
          best_sq[at] = d_sq;
          cells_[at] = static_cast<std::int32_t>(i);
        }
      }
    }
  }
}

}  // namespace tofnav
