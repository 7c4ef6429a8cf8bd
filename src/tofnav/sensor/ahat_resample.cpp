// SPDX-License-Identifier: BSD-3-Clause
// Resampling of a unit-plane table at a constant sub-entry shift (the c - s of docs/ahat.md 5.3).
#include <array>
#include <cmath>
#include <limits>

#include "tofnav/sensor/ahat_table.hpp"

namespace tofnav {
namespace {

constexpr int kTaps = 4;
/// Stencil starts relative to the bracketing entry i0, most centred first; the others serve
/// entries next to the border or the mask edge.
constexpr std::array<int, 3> kStencilStarts = {-1, 0, -2};

/// Weights of the cubic through the nodes start .. start + 3 (relative to i0) at fraction t.
std::array<double, kTaps> LagrangeWeights(int start, double t) {
  std::array<double, kTaps> weights{};
  for (int k = 0; k < kTaps; ++k) {
    weights[k] = 1.0;
    for (int m = 0; m < kTaps; ++m) {
      if (m != k) weights[k] *= (t - (start + m)) / static_cast<double>(k - m);
    }
  }
  return weights;
}

/// Summed-area table of a mask: counts of valid entries in any rectangle in O(1).
class MaskSums {
 public:
  explicit MaskSums(const Mask& mask) : sums_(mask.width() + 1, mask.height() + 1, 0) {
    for (int v = 0; v < mask.height(); ++v) {
      for (int u = 0; u < mask.width(); ++u) {
        sums_(u + 1, v + 1) = sums_(u, v + 1) + sums_(u + 1, v) - sums_(u, v) + (mask(u, v) != 0);
      }
    }
  }
  /// True when the n x n block starting at (u, v) lies inside and is all valid.
  bool AllValid(int u, int v, int n) const {
    if (u < 0 || v < 0 || u + n >= sums_.width() || v + n >= sums_.height()) return false;
    return sums_(u + n, v + n) - sums_(u, v + n) - sums_(u + n, v) + sums_(u, v) == n * n;
  }

 private:
  Image<int> sums_;
};

}  // namespace

ResampledTable ResampleTable(const UnitPlaneTable& table, const Mask& entry_valid,
                             double shift_px) {
  const int width = table.width();
  const int height = table.height();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  ResampledTable out{UnitPlaneTable(width, height, PlanePoint{nan, nan}), Mask(width, height)};
  const double floor_shift = std::floor(shift_px);
  const int offset = static_cast<int>(floor_shift);
  const double t = shift_px - floor_shift;  // the same fraction for every entry
  const int bracket = t > 0.0 ? 2 : 1;      // entries with a non-zero bilinear weight per axis
  const MaskSums sums(entry_valid);
  std::array<std::array<double, kTaps>, kStencilStarts.size()> weights{};
  for (std::size_t k = 0; k < kStencilStarts.size(); ++k) {
    weights[k] = LagrangeWeights(kStencilStarts[k], t);
  }
  for (int v = 0; v < height; ++v) {
    const int j0 = v + offset;
    for (int u = 0; u < width; ++u) {
      const int i0 = u + offset;
      if (!sums.AllValid(i0, j0, bracket)) continue;
      out.valid(u, v) = 1;
      if (bracket == 1) {
        out.table(u, v) = table(i0, j0);
        continue;
      }
      // Cubic where a valid 4 x 4 stencil brackets the point, else bilinear.
      double x = 0.0;
      double y = 0.0;
      bool done = false;
      for (std::size_t sv = 0; sv < kStencilStarts.size() && !done; ++sv) {
        for (std::size_t su = 0; su < kStencilStarts.size() && !done; ++su) {
          const int first_i = i0 + kStencilStarts[su];
          const int first_j = j0 + kStencilStarts[sv];
          if (!sums.AllValid(first_i, first_j, kTaps)) continue;
          const double* wu = weights[su].data();
          const double* wv = weights[sv].data();
          for (int l = 0; l < kTaps; ++l) {
            for (int k = 0; k < kTaps; ++k) {
              const PlanePoint& q = table(first_i + k, first_j + l);
              x += wu[k] * wv[l] * q.x;
              y += wu[k] * wv[l] * q.y;
            }
          }
          done = true;
        }
      }
      if (!done) {
        const double w[2] = {1.0 - t, t};
        for (int l = 0; l < 2; ++l) {
          for (int k = 0; k < 2; ++k) {
            const PlanePoint& q = table(i0 + k, j0 + l);
            x += w[k] * w[l] * q.x;
            y += w[k] * w[l] * q.y;
          }
        }
      }
      out.table(u, v) = {static_cast<float>(x), static_cast<float>(y)};
    }
  }
  return out;
}

}  // namespace tofnav
