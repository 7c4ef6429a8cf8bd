// SPDX-License-Identifier: BSD-3-Clause
// The AB that the depth model's intensity term C4 ln(AB_ref / AB) reads (docs/correction.md 2.10).
#pragma once

#include <cstdint>

#include "tofnav/core/image.hpp"

namespace tofnav {

/// Each pixel's AB in counts: a lossy stream's square code (AhatFrame::ab_lossy; hl2ss's clients
/// recover AB = c^2) read at the centre (c + 1/2)^2 of the interval [c^2, (c + 1)^2) the code
/// stands for (docs/correction.md 7.2), any other AB as it is.
Image<float> DecodedAb(const Image<std::uint16_t>& ab, bool square_code);

/// The intensity term's AB is the surface's signal amplitude, which varies smoothly over the skin;
/// one pixel's AB scatters around it (shot noise, and on a lossy stream the square code's steps:
/// at AB 16 one code step is 0.5 in ln AB), and hl2ss's floor reading c^2 lies below it. Read per
/// pixel, the scatter goes through C4 into the range, and in the identification it is noise on a
/// regressor. The window's mean of the codes' interval centres scatters several times less and is
/// unbiased; on the suite it did not improve the lines (docs/correction.md 2.10), so it is off by
/// default.
struct IntensityAbOptions {
  bool window_mean = false;  // false: each pixel's AB as the frame holds it (hl2ss's c^2)
  int radius_px = 3;         // 7 x 7 pixels, 8 mm at 500 mm
  /// A window pixel lies on the pixel's surface when its range differs by at most this per pixel
  /// of offset (the larger of |du| and |dv|) [mm]: 5 mm/px is a slope of 78 deg at 500 mm (1.1 mm
  /// pixels); a marker's or the background's range step is tens of millimetres.
  double same_surface_mm_per_px = 5.0;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

/// The intensity term's AB at (u, v). With window_mean: the mean `decoded_ab` (DecodedAb of the
/// frame) of the window's pixels on the same surface as (u, v) (range > 0 in `surface_range_mm`,
/// within the slope limit), (u, v) included, or its own decoded AB when it has no range. Without:
/// the frame's AB `ab` at (u, v) as it is.
double IntensityAbAt(const Image<std::uint16_t>& ab, const Image<float>& decoded_ab,
                     const Image<float>& surface_range_mm, int u, int v,
                     const IntensityAbOptions& options);

}  // namespace tofnav
