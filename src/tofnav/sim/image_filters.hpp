// SPDX-License-Identifier: BSD-3-Clause
// Separable Gaussian filters on real and complex images (lens-scatter PSF, correlated noise).
#pragma once

#include <complex>

#include "tofnav/core/image.hpp"

namespace tofnav::sim {

/// A rectangle of pixels; filters treat everything outside it as zero and leave it unchanged.
struct PixelRect {
  int u0 = 0;
  int v0 = 0;
  int width = 0;
  int height = 0;
};

/// In-place Gaussian blur of `rect` with a normalised kernel of radius ceil(3 sigma) [px],
/// zero-padded at the rect's border (light that leaves the rect is lost).
void GaussianBlur(Image<double>& image, const PixelRect& rect, double sigma_px);
void GaussianBlur(Image<std::complex<double>>& image, const PixelRect& rect, double sigma_px);

/// In-place approximate Gaussian blur by three box passes per axis (Kovesi's widths): O(1) per
/// pixel whatever sigma, for wide kernels. Zero-padded like GaussianBlur.
void BoxGaussianBlur(Image<std::complex<double>>& image, const PixelRect& rect, double sigma_px);

/// Sum of the squared 1D Gaussian kernel weights of GaussianBlur: a separable 2D blur scales the
/// standard deviation of white noise by this factor.
double GaussianNoiseGain(double sigma_px);

}  // namespace tofnav::sim
