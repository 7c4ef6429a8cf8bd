// SPDX-License-Identifier: BSD-3-Clause
// Separable squared Euclidean distance transform: the lower envelope of parabolas per line.
#include "tofnav/core/distance_transform.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// 1D squared distance transform of sampled f (Felzenszwalb & Huttenlocher 2012), spacing h.
void DistanceTransform1d(std::vector<double>& f, double h, std::vector<int>& v,
                         std::vector<double>& z) {
  const int n = static_cast<int>(f.size());
  v.assign(f.size(), 0);
  z.assign(f.size() + 1, 0.0);
  int count = -1;  // index of the last parabola of the lower envelope
  for (int q = 0; q < n; ++q) {
    if (!std::isfinite(f[static_cast<std::size_t>(q)])) continue;
    const double fq = f[static_cast<std::size_t>(q)] + (q * h) * (q * h);
    double s = -kInfinity;
    while (count >= 0) {
      const int p = v[static_cast<std::size_t>(count)];
      s = (fq - (f[static_cast<std::size_t>(p)] + (p * h) * (p * h))) / (2.0 * h * (q - p));
      if (s > z[static_cast<std::size_t>(count)]) break;
      --count;
    }
    ++count;
    v[static_cast<std::size_t>(count)] = q;
    z[static_cast<std::size_t>(count)] = count == 0 ? -kInfinity : s;
    z[static_cast<std::size_t>(count) + 1] = kInfinity;
  }
  if (count < 0) return;  // nothing finite on this line yet
  const std::vector<double> sampled = f;
  int k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[static_cast<std::size_t>(k) + 1] < q * h) ++k;
    const int p = v[static_cast<std::size_t>(k)];
    f[static_cast<std::size_t>(q)] =
        (q - p) * h * (q - p) * h + sampled[static_cast<std::size_t>(p)];
  }
}

}  // namespace

void SquaredDistanceTransform(std::vector<double>& d2, const std::array<int, 3>& dims,
                              const std::array<double, 3>& spacing_mm) {
  Require(dims[0] >= 0 && dims[1] >= 0 && dims[2] >= 0,
          "SquaredDistanceTransform: dimensions must be >= 0");
  Require(d2.size() == static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1]) *
                           static_cast<std::size_t>(dims[2]),
          "SquaredDistanceTransform: d2.size() must equal nx * ny * nz");
  for (const double h : spacing_mm) {
    Require(std::isfinite(h) && h > 0.0, "SquaredDistanceTransform: spacing must be > 0");
  }
  const std::array<std::size_t, 3> strides = {
      1, static_cast<std::size_t>(dims[0]),
      static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1])};
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const std::size_t a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    const auto n_axis = static_cast<std::size_t>(dims[axis]);
    const auto n1 = static_cast<std::int64_t>(dims[a1]);
    const auto n2 = static_cast<std::int64_t>(dims[a2]);
    ParallelFor(0, n1 * n2, [&](std::int64_t line) {
      const std::size_t base = static_cast<std::size_t>(line % n1) * strides[a1] +
                               static_cast<std::size_t>(line / n1) * strides[a2];
      std::vector<double> f(n_axis);
      std::vector<int> v;
      std::vector<double> z;
      for (std::size_t q = 0; q < n_axis; ++q) f[q] = d2[base + q * strides[axis]];
      DistanceTransform1d(f, spacing_mm[axis], v, z);
      for (std::size_t q = 0; q < n_axis; ++q) d2[base + q * strides[axis]] = f[q];
    });
  }
}

}  // namespace tofnav
