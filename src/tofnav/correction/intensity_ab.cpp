// SPDX-License-Identifier: BSD-3-Clause
// The AB that the depth model's intensity term reads (docs/correction.md 2.10).
#include "tofnav/correction/intensity_ab.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace tofnav {

Image<float> DecodedAb(const Image<std::uint16_t>& ab, bool square_code) {
  Image<float> out(ab.width(), ab.height());
  for (std::size_t i = 0; i < ab.size(); ++i) {
    const double x = ab.pixels()[i];
    if (!square_code || x <= 0.0) {
      out.pixels()[i] = static_cast<float>(x);
      continue;
    }
    const double code = std::floor(std::sqrt(x));
    out.pixels()[i] = static_cast<float>((code + 0.5) * (code + 0.5));
  }
  return out;
}

void IntensityAbOptions::Check() const {
  if (radius_px < 0 || radius_px > 16) {
    throw std::invalid_argument("IntensityAbOptions: radius_px must lie in [0, 16]");
  }
  if (!(same_surface_mm_per_px > 0.0) || !std::isfinite(same_surface_mm_per_px)) {
    throw std::invalid_argument("IntensityAbOptions: same_surface_mm_per_px must be > 0");
  }
}

double IntensityAbAt(const Image<std::uint16_t>& ab, const Image<float>& decoded_ab,
                     const Image<float>& surface_range_mm, int u, int v,
                     const IntensityAbOptions& options) {
  if (!options.window_mean) return ab(u, v);
  const double own = decoded_ab(u, v);
  const double centre_mm = surface_range_mm(u, v);
  if (centre_mm <= 0.0) return own;
  const int r = options.radius_px;
  double sum = 0.0;
  int count = 0;
  for (int y = std::max(0, v - r); y <= std::min(decoded_ab.height() - 1, v + r); ++y) {
    for (int x = std::max(0, u - r); x <= std::min(decoded_ab.width() - 1, u + r); ++x) {
      const double d = surface_range_mm(x, y);
      const double value = decoded_ab(x, y);
      if (d <= 0.0 || value <= 0.0) continue;
      const int offset_px = std::max(std::abs(x - u), std::abs(y - v));
      if (std::abs(d - centre_mm) > options.same_surface_mm_per_px * offset_px) continue;
      sum += value;
      ++count;
    }
  }
  return count > 0 ? sum / count : own;
}

}  // namespace tofnav
