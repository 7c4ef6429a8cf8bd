// SPDX-License-Identifier: BSD-3-Clause
// A dense grid that answers "which sample lies near here" with one lookup: for scoring tens of
// thousands of coarse placements, where a KD-tree query per sample point is too slow.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "tofnav/core/point_cloud.hpp"

namespace tofnav {

class NearestSampleGrid {
 public:
  /// Each cell of edge `cell_mm` stores the sample nearest its centre among those within
  /// `reach_mm` + half a cell diagonal (ties: the lower index), so any query within `reach_mm` of
  /// a sample finds a sample at most one cell diagonal farther than its true nearest.
  NearestSampleGrid(const Points3d& samples, double cell_mm, double reach_mm);

  /// The stored sample of the query's cell, if any (not necessarily within reach: check).
  std::optional<std::uint32_t> Lookup(const Eigen::Vector3d& query) const {
    return Lookup(query.data());
  }
  /// The same for a query given as 3 doubles: plain scalars, as this runs for every sample of
  /// every placement (unoptimised builds too).
  std::optional<std::uint32_t> Lookup(const double* query) const {
    const double x = std::floor((query[0] - origin_[0]) * inverse_cell_);
    const double y = std::floor((query[1] - origin_[1]) * inverse_cell_);
    const double z = std::floor((query[2] - origin_[2]) * inverse_cell_);
    if (!(x >= 0.0 && y >= 0.0 && z >= 0.0 && x < size_d_[0] && y < size_d_[1] && z < size_d_[2])) {
      return std::nullopt;
    }
    const auto at = static_cast<std::size_t>(
        (static_cast<std::int64_t>(z) * size_[1] + static_cast<std::int64_t>(y)) * size_[0] +
        static_cast<std::int64_t>(x));
    const std::int32_t index = cells_[at];
    if (index < 0) return std::nullopt;
    return static_cast<std::uint32_t>(index);
  }

 private:
  double origin_[3];
  double inverse_cell_;
  std::int64_t size_[3];
  double size_d_[3];                 // size_ as doubles, for the bounds test
  std::vector<std::int32_t> cells_;  // sample index or -1
};

}  // namespace tofnav
