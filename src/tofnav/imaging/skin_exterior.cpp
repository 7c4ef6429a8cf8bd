// SPDX-License-Identifier: BSD-3-Clause
// The air outside the head (docs/registration.md 1.): face seeds and the probe-ball fill.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "tofnav/core/distance_transform.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/imaging/skin_mask.hpp"

namespace tofnav {
namespace {

constexpr std::uint8_t kExteriorBackground = 0, kExteriorTissue = 1;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

std::size_t VoxelCount(const std::array<int, 3>& dims) {
  return static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1]) *
         static_cast<std::size_t>(dims[2]);
}

void CheckMask(const VoxelMask& mask, const char* what) {
  Require(mask.dims[0] > 0 && mask.dims[1] > 0 && mask.dims[2] > 0 &&
              mask.values.size() == VoxelCount(mask.dims),
          std::string(what) + ": mask size != nx * ny * nz");
}

/// 6-connected flood over voxels where `open` is set, from every seed; sets `reached`.
void Flood(const std::array<int, 3>& dims, const std::vector<std::uint8_t>& open,
           std::vector<std::size_t> stack, std::vector<std::uint8_t>& reached) {
  const std::size_t sy = static_cast<std::size_t>(dims[0]),
                    sz = sy * static_cast<std::size_t>(dims[1]);
  for (const std::size_t v : stack) reached[v] = 1;
  while (!stack.empty()) {
    const std::size_t v = stack.back();
    stack.pop_back();
    const std::size_t i = v % sy, j = (v / sy) % static_cast<std::size_t>(dims[1]), k = v / sz;
    const auto visit = [&](std::size_t w) {
      if (open[w] != 0 && reached[w] == 0) {
        reached[w] = 1;
        stack.push_back(w);
      }
    };
    if (i > 0) visit(v - 1);
    if (i + 1 < sy) visit(v + 1);
    if (j > 0) visit(v - sy);
    if (j + 1 < static_cast<std::size_t>(dims[1])) visit(v + sy);
    if (k > 0) visit(v - sz);
    if (k + 1 < static_cast<std::size_t>(dims[2])) visit(v + sz);
  }
}

bool OnBorder(const std::array<int, 3>& dims, int i, int j, int k) {
  return i == 0 || j == 0 || k == 0 || i + 1 == dims[0] || j + 1 == dims[1] || k + 1 == dims[2];
}

}  // namespace

std::vector<std::uint8_t> ExteriorFaceSeeds(const VoxelMask& mask) {
  CheckMask(mask, "ExteriorFaceSeeds");
  const std::array<std::size_t, 3> dims = {static_cast<std::size_t>(mask.dims[0]),
                                           static_cast<std::size_t>(mask.dims[1]),
                                           static_cast<std::size_t>(mask.dims[2])};
  const std::array<std::size_t, 3> strides = {1, dims[0], dims[0] * dims[1]};
  std::vector<std::uint8_t> seeds(mask.values.size(), 0);
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const std::size_t u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
    const std::size_t nu = dims[u_axis], nv = dims[v_axis];
    for (const std::size_t layer : {std::size_t{0}, dims[axis] - 1}) {
      // A 4-connected fill within the face from its rim (the volume's edges).
      const std::size_t base = layer * strides[axis];
      const auto at = [&](std::size_t u, std::size_t v) {
        return base + u * strides[u_axis] + v * strides[v_axis];
      };
      std::vector<std::uint8_t> reached(nu * nv, 0);
      const auto enter = [&](std::size_t u, std::size_t v) {
        if (mask.values[at(u, v)] != kExteriorBackground || reached[u + nu * v] != 0) return false;
        reached[u + nu * v] = 1;
        seeds[at(u, v)] = 1;
        return true;
      };
      FloodPlaneFromRim(nu, nv, enter, enter);
    }
  }
  return seeds;
}

std::size_t FillUnreachableAir(VoxelMask& mask, const std::array<double, 3>& spacing_mm,
                               double ball_radius_mm, const std::vector<std::uint8_t>& seeds) {
  CheckMask(mask, "FillUnreachableAir");
  Require(seeds.size() == mask.values.size(), "FillUnreachableAir: seeds size != mask size");
  Require(std::isfinite(ball_radius_mm) && ball_radius_mm > 0.0,
          "FillUnreachableAir: ball_radius_mm must be > 0");
  // Beyond each face the grid is padded with the face itself: its exterior air stays air,
  // tissue and the head's cut interior become tissue, so the ball rolls past the border.
  std::array<int, 3> pad{}, dims{};
  for (std::size_t a = 0; a < 3; ++a) {
    Require(std::isfinite(spacing_mm[a]) && spacing_mm[a] > 0.0,
            "FillUnreachableAir: spacing must be > 0");
    pad[a] = static_cast<int>(std::ceil(ball_radius_mm / spacing_mm[a])) + 1;
    dims[a] = mask.dims[a] + 2 * pad[a];
  }
  const std::size_t count = VoxelCount(dims);
  std::vector<double> d2(count);
  std::vector<std::uint8_t> air(count);
  const auto source = [&](int i, int j, int k) {
    const int ci = std::clamp(i - pad[0], 0, mask.dims[0] - 1);
    const int cj = std::clamp(j - pad[1], 0, mask.dims[1] - 1);
    const int ck = std::clamp(k - pad[2], 0, mask.dims[2] - 1);
    return static_cast<std::size_t>(ci) +
           static_cast<std::size_t>(mask.dims[0]) *
               (static_cast<std::size_t>(cj) +
                static_cast<std::size_t>(mask.dims[1]) * static_cast<std::size_t>(ck));
  };
  const auto inside = [&](int i, int j, int k) {
    return i >= pad[0] && j >= pad[1] && k >= pad[2] && i < pad[0] + mask.dims[0] &&
           j < pad[1] + mask.dims[1] && k < pad[2] + mask.dims[2];
  };
  std::size_t n = 0;
  for (int k = 0; k < dims[2]; ++k) {
    for (int j = 0; j < dims[1]; ++j) {
      for (int i = 0; i < dims[0]; ++i, ++n) {
        const std::size_t s = source(i, j, k);
        const bool is_air =
            mask.values[s] == kExteriorBackground && (inside(i, j, k) || seeds[s] != 0);
        air[n] = is_air ? 1 : 0;
        d2[n] = is_air ? kInfinity : 0.0;
      }
    }
  }
  // Where the ball's centre fits (farther than its radius from tissue), reached from the border.
  SquaredDistanceTransform(d2, dims, spacing_mm);
  const double r2 = ball_radius_mm * ball_radius_mm;
  std::vector<std::uint8_t> fits(count), reached(count, 0);
  std::vector<std::size_t> stack;
  n = 0;
  for (int k = 0; k < dims[2]; ++k) {
    for (int j = 0; j < dims[1]; ++j) {
      for (int i = 0; i < dims[0]; ++i, ++n) {
        fits[n] = air[n] != 0 && d2[n] > r2 ? 1 : 0;
        if (fits[n] != 0 && OnBorder(dims, i, j, k)) stack.push_back(n);
      }
    }
  }
  Flood(dims, fits, std::move(stack), reached);
  // The air the ball sweeps: within its radius of a reached centre. What it misses is filled
  // only where it reaches deeper than another radius (a canal, a cavity): the sliver it misses
  // in a concave corner (at most r (sqrt 2 - 1) deep at 90 degrees) is real, visible skin.
  for (std::size_t v = 0; v < count; ++v) d2[v] = reached[v] != 0 ? 0.0 : kInfinity;
  SquaredDistanceTransform(d2, dims, spacing_mm);
  std::vector<std::uint8_t>& missed = fits;  // reused: air the ball does not sweep
  stack.clear();                             // moved from
  for (std::size_t v = 0; v < count; ++v) {
    missed[v] = air[v] != 0 && d2[v] > r2 ? 1 : 0;
    if (d2[v] > 4.0 * r2 && missed[v] != 0) stack.push_back(v);
  }
  std::fill(reached.begin(), reached.end(), std::uint8_t{0});
  Flood(dims, missed, std::move(stack), reached);
  std::size_t filled = 0;
  n = 0;
  for (int k = 0; k < dims[2]; ++k) {
    for (int j = 0; j < dims[1]; ++j) {
      for (int i = 0; i < dims[0]; ++i, ++n) {
        if (!inside(i, j, k) || reached[n] == 0) continue;
        mask.values[source(i, j, k)] = kExteriorTissue;
        ++filled;
      }
    }
  }
  return filled;
}

}  // namespace tofnav
