// SPDX-License-Identifier: BSD-3-Clause
// The separable Euclidean distance transform of a voxel grid (Felzenszwalb & Huttenlocher 2012).
#pragma once

#include <array>
#include <vector>

namespace tofnav {

/// In place: on entry `d2` holds 0 at the feature voxels and +infinity elsewhere, voxel (i, j, k)
/// at i + nx * (j + ny * k); on return the squared distance [mm^2] from each voxel centre to the
/// nearest feature voxel centre (+infinity when the grid has none). `spacing_mm` per axis (> 0).
/// Exact, O(voxels), lines in parallel; the result does not depend on the thread count.
void SquaredDistanceTransform(std::vector<double>& d2, const std::array<int, 3>& dims,
                              const std::array<double, 3>& spacing_mm);

}  // namespace tofnav
