// SPDX-License-Identifier: BSD-3-Clause
// Binary mask operations of the skin extraction: largest 6-connected component, slice fill.
#include "tofnav/imaging/skin_mask.hpp"

#include <algorithm>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr std::uint8_t kBackground = 0, kTissue = 1, kReached = 2;

}  // namespace

int KeepLargestComponent(VoxelMask& mask) {
  const auto [nx, ny, nz] = mask.dims;
  const std::size_t count = mask.values.size();
  Require(count == static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) *
                       static_cast<std::size_t>(nz),
          "KeepLargestComponent: mask size != nx * ny * nz");
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
  const auto largest =
      static_cast<std::int32_t>(std::max_element(sizes.begin(), sizes.end()) - sizes.begin());
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
