// SPDX-License-Identifier: BSD-3-Clause
// Binary mask operations of the skin extraction: largest 6-connected component, slice fill.
#include "tofnav/imaging/skin_mask.hpp"

#include <algorithm>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr std::uint8_t kBackground = 0, kTissue = 1, kReached = 2;
/// A component counts as seen from outside when the axis rays from the exterior hit it first at
/// least this often relative to the most-hit one: the scalp of an MR head cut below the skull
/// base is seen everywhere, the brain (its own component there) only down an ear canal.
constexpr double kMinSeenFraction = 0.1;

}  // namespace

int KeepOuterComponent(VoxelMask& mask, const std::vector<std::uint8_t>& seeds) {
  const auto [nx, ny, nz] = mask.dims;
  const std::size_t count = mask.values.size();
  Require(count == static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) *
                       static_cast<std::size_t>(nz),
          "KeepOuterComponent: mask size != nx * ny * nz");
  Require(seeds.size() == count, "KeepOuterComponent: seeds size != mask size");
  const std::size_t sx = 1, sy = static_cast<std::size_t>(nx),
                    sz = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  std::vector<std::int32_t> labels(count, -1);
  std::vector<std::size_t> sizes;
  std::vector<std::size_t> stack;
  for (std::size_t seed = 0; seed < count; ++seed) {
    if (mask.values[seed] != kTissue || labels[seed] >= 0) continue;
    const auto label = static_cast<std::int32_t>(sizes.size());
    std::size_t size = 0;
    labels[seed] = label;
    stack.push_back(seed);
    while (!stack.empty()) {
      const std::size_t v = stack.back();
      stack.pop_back();
      ++size;
      const std::size_t i = v % sy, j = (v / sy) % static_cast<std::size_t>(ny), k = v / sz;
      const auto visit = [&](std::size_t w) {
        if (mask.values[w] == kTissue && labels[w] < 0) {
          labels[w] = label;
          stack.push_back(w);
        }
      };
      if (i > 0) visit(v - sx);
      if (i + 1 < static_cast<std::size_t>(nx)) visit(v + sx);
      if (j > 0) visit(v - sy);
      if (j + 1 < static_cast<std::size_t>(ny)) visit(v + sy);
      if (k > 0) visit(v - sz);
      if (k + 1 < static_cast<std::size_t>(nz)) visit(v + sz);
    }
    sizes.push_back(size);
  }
  if (sizes.empty()) return 0;
  // Votes: rays along the axes from each exterior face voxel, for the component they hit first.
  const std::array<std::size_t, 3> dims = {
      static_cast<std::size_t>(nx), static_cast<std::size_t>(ny), static_cast<std::size_t>(nz)};
  const std::array<std::size_t, 3> strides = {sx, sy, sz};
  std::vector<std::size_t> votes(sizes.size(), 0);
  for (std::size_t v = 0; v < count; ++v) {
    if (seeds[v] == 0) continue;
    const std::array<std::size_t, 3> ijk = {v % sy, (v / sy) % dims[1], v / sz};
    for (std::size_t axis = 0; axis < 3; ++axis) {
      const std::size_t n = dims[axis], stride = strides[axis];
      if (ijk[axis] != 0 && ijk[axis] + 1 != n) continue;  // not on a face normal to axis
      const bool forward = ijk[axis] == 0;
      std::size_t w = v;
      for (std::size_t step = 0; step < n; ++step, w = forward ? w + stride : w - stride) {
        if (labels[w] < 0) continue;
        ++votes[static_cast<std::size_t>(labels[w])];
        break;
      }
    }
  }
  const std::size_t most_votes = *std::max_element(votes.begin(), votes.end());
  std::int32_t largest = -1;
  for (std::size_t c = 0; c < sizes.size(); ++c) {
    const bool seen =
        static_cast<double>(votes[c]) >= kMinSeenFraction * static_cast<double>(most_votes);
    if (seen && (largest < 0 || sizes[c] > sizes[static_cast<std::size_t>(largest)])) {
      largest = static_cast<std::int32_t>(c);
    }
  }
  for (std::size_t v = 0; v < count; ++v) {
    mask.values[v] = labels[v] == largest ? kTissue : kBackground;
  }
  return static_cast<int>(sizes.size());
}

std::size_t FillSliceCavities(VoxelMask& mask, int axis, const std::vector<std::uint8_t>& seeds) {
  Require(axis >= 0 && axis < 3, "FillSliceCavities: axis must be 0, 1 or 2");
  Require(seeds.size() == mask.values.size(), "FillSliceCavities: seeds size != mask size");
  const std::array<std::size_t, 3> dims = {static_cast<std::size_t>(mask.dims[0]),
                                           static_cast<std::size_t>(mask.dims[1]),
                                           static_cast<std::size_t>(mask.dims[2])};
  Require(mask.values.size() == dims[0] * dims[1] * dims[2],
          "FillSliceCavities: mask size != nx * ny * nz");
  const std::array<std::size_t, 3> strides = {1, dims[0], dims[0] * dims[1]};
  const auto u_axis = static_cast<std::size_t>((axis + 1) % 3);
  const auto v_axis = static_cast<std::size_t>((axis + 2) % 3);
  const std::size_t nu = dims[u_axis], nv = dims[v_axis];
  const std::size_t su = strides[u_axis], sv = strides[v_axis];
  const std::size_t slices = dims[static_cast<std::size_t>(axis)];
  std::vector<std::size_t> filled(slices, 0);
  // Each slice touches only its own voxels: parallel and deterministic.
  ParallelFor(0, static_cast<std::int64_t>(slices), [&](std::int64_t slice) {
    const std::size_t base =
        static_cast<std::size_t>(slice) * strides[static_cast<std::size_t>(axis)];
    const auto enter = [&](std::size_t u, std::size_t v) {
      std::uint8_t& value = mask.values[base + u * su + v * sv];
      if (value != kBackground) return false;
      value = kReached;
      return true;
    };
    FloodPlaneFromRim(
        nu, nv,
        [&](std::size_t u, std::size_t v) {
          return seeds[base + u * su + v * sv] != 0 && enter(u, v);
        },
        enter);
    for (std::size_t v = 0; v < nv; ++v) {
      for (std::size_t u = 0; u < nu; ++u) {
        std::uint8_t& value = mask.values[base + u * su + v * sv];
        if (value == kBackground) {
          value = kTissue;
          ++filled[static_cast<std::size_t>(slice)];
        } else if (value == kReached) {
          value = kBackground;
        }
      }
    }
  });
  std::size_t total = 0;
  for (const std::size_t n : filled) total += n;
  return total;
}

}  // namespace tofnav
