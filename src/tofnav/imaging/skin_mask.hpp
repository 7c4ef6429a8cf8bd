// SPDX-License-Identifier: BSD-3-Clause
// Internal to imaging/: binary mask operations of the skin extraction (components, air fills).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace tofnav {

/// A binary volume, voxel (i, j, k) at i + nx * (j + ny * k); 1 = tissue.
struct VoxelMask {
  std::array<int, 3> dims = {0, 0, 0};
  std::vector<std::uint8_t> values;
};

/// 4-connected flood over an nu x nv plane from its rim: `enter_rim(u, v)` and `enter(u, v)`
/// return whether (u, v) is entered now (they mark it), for the rim and for a neighbour.
template <class EnterRim, class Enter>
void FloodPlaneFromRim(std::size_t nu, std::size_t nv, EnterRim&& enter_rim, Enter&& enter) {
  std::vector<std::pair<std::size_t, std::size_t>> stack;
  const auto rim = [&](std::size_t u, std::size_t v) {
    if (enter_rim(u, v)) stack.emplace_back(u, v);
  };
  for (std::size_t u = 0; u < nu; ++u) rim(u, 0), rim(u, nv - 1);
  for (std::size_t v = 0; v < nv; ++v) rim(0, v), rim(nu - 1, v);
  const auto visit = [&](std::size_t u, std::size_t v) {
    if (enter(u, v)) stack.emplace_back(u, v);
  };
  while (!stack.empty()) {
    const auto [u, v] = stack.back();
    stack.pop_back();
    if (u > 0) visit(u - 1, v);
    if (u + 1 < nu) visit(u + 1, v);
    if (v > 0) visit(u, v - 1);
    if (v + 1 < nv) visit(u, v + 1);
  }
}

/// Keeps the largest 6-connected component of the mask among those seen from outside: hit
/// first by rays along the voxel axes from the exterior face voxels (`seeds`, of
/// ExteriorFaceSeeds) at least a tenth as often as the most-hit component (ties: the one met
/// first in memory order). Returns the number of components there were.
int KeepOuterComponent(VoxelMask& mask, const std::vector<std::uint8_t>& seeds);

/// Background voxels on the volume's six faces that lie outside the head: reachable, within
/// their face, from the face's rim (the volume's edges). Background enclosed by tissue on a face
/// is the inside of a head cut by the field of view (airway, skull in MR). 1 = seed, per voxel.
std::vector<std::uint8_t> ExteriorFaceSeeds(const VoxelMask& mask);

/// Sets the background enclosed within each slice normal to `axis` (0, 1, 2): the 4-connected
/// background not reachable from the slice's exterior border voxels (`seeds`, of
/// ExteriorFaceSeeds). Returns the number of voxels filled.
std::size_t FillSliceCavities(VoxelMask& mask, int axis, const std::vector<std::uint8_t>& seeds);

/// Sets the background that a ball of `ball_radius_mm` rolled in from outside the volume (through
/// the exterior face seeds) cannot sweep: cavities, and air behind openings narrower than the
/// ball (ear canals, nostrils, the skull's dark band in MR reached through them), where the
/// missed air reaches deeper than two radii from the ball's centres; shallower slivers (concave
/// corners) stay air, so the visible skin is kept exactly. Returns the number of voxels filled.
std::size_t FillUnreachableAir(VoxelMask& mask, const std::array<double, 3>& spacing_mm,
                               double ball_radius_mm, const std::vector<std::uint8_t>& seeds);

}  // namespace tofnav
