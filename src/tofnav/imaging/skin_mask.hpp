// SPDX-License-Identifier: BSD-3-Clause
// Internal to imaging/: binary mask operations of the skin extraction (components, cavity fill).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace tofnav {

/// A binary volume, voxel (i, j, k) at i + nx * (j + ny * k); 1 = tissue.
struct VoxelMask {
  std::array<int, 3> dims = {0, 0, 0};
  std::vector<std::uint8_t> values;
};

/// Keeps the largest 6-connected component of the mask (ties: the one met first in memory
/// order) and returns the number of components there were.
int KeepLargestComponent(VoxelMask& mask);

/// Sets the background enclosed within each slice normal to `axis` (0, 1, 2): the 4-connected
/// background not reachable from the slice's border. Returns the number of voxels filled.
std::size_t FillSliceCavities(VoxelMask& mask, int axis);

}  // namespace tofnav
