// SPDX-License-Identifier: BSD-3-Clause
// Separable Gaussian filters on real and complex images, row-major in both passes.
#include "tofnav/sim/image_filters.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"

namespace tofnav::sim {
namespace {

constexpr std::int64_t kRowsPerTask = 8;

std::vector<double> GaussianKernel(double sigma_px) {
  const int radius = std::max(1, static_cast<int>(std::ceil(3.0 * sigma_px)));
  std::vector<double> kernel(static_cast<std::size_t>(2 * radius + 1));
  double sum = 0.0;
  for (int k = -radius; k <= radius; ++k) {
    const double w = std::exp(-0.5 * k * k / (sigma_px * sigma_px));
    kernel[static_cast<std::size_t>(k + radius)] = w;
    sum += w;
  }
  for (double& w : kernel) w /= sum;
  return kernel;
}

// Widths of three box filters whose cascade has standard deviation sigma (Kovesi 2010).
std::array<int, 3> BoxWidths(double sigma_px) {
  constexpr int kPasses = 3;
  const double ideal = std::sqrt(12.0 * sigma_px * sigma_px / kPasses + 1.0);
  int lower = static_cast<int>(std::floor(ideal));
  if (lower % 2 == 0) --lower;
  const int upper = lower + 2;
  const double m = (12.0 * sigma_px * sigma_px - kPasses * lower * lower - 4.0 * kPasses * lower -
                    3.0 * kPasses) /
                   (-4.0 * lower - 4.0);
  const int lower_count = static_cast<int>(std::lround(m));
  std::array<int, 3> widths{};
  for (int i = 0; i < kPasses; ++i) {
    widths[static_cast<std::size_t>(i)] = i < lower_count ? lower : upper;
  }
  return widths;
}

// A rect copied out of an image, row-major; passes read `src` and write `dst`, then swap.
template <typename T>
struct Planes {
  int width = 0, height = 0;
  std::vector<T> src, dst;
  T* Row(std::vector<T>& plane, int v) {
    return plane.data() + static_cast<std::size_t>(v) * width;
  }
};

template <typename T>
Planes<T>& LoadPlanes(const Image<T>& image, const PixelRect& rect) {
  Require(rect.u0 >= 0 && rect.v0 >= 0 && rect.width >= 0 && rect.height >= 0 &&
              rect.u0 + rect.width <= image.width() && rect.v0 + rect.height <= image.height(),
          "filter rect outside the image");
  thread_local Planes<T> reused;  // reused across calls: no page faults per frame
  Planes<T>& planes = reused;     // a reference, so worker threads see this thread's planes
  planes.width = rect.width;
  planes.height = rect.height;
  const std::size_t size =
      static_cast<std::size_t>(rect.width) * static_cast<std::size_t>(rect.height);
  planes.src.resize(size);
  planes.dst.resize(size);
  ParallelFor(
      0, rect.height,
      [&](std::int64_t row) {
        const int v = static_cast<int>(row);
        std::copy_n(&image(rect.u0, rect.v0 + v), rect.width, planes.Row(planes.src, v));
      },
      kRowsPerTask);
  return planes;
}

template <typename T>
void StorePlanes(Planes<T>& planes, Image<T>& image, const PixelRect& rect) {
  ParallelFor(
      0, rect.height,
      [&](std::int64_t row) {
        const int v = static_cast<int>(row);
        std::copy_n(planes.Row(planes.src, v), rect.width, &image(rect.u0, rect.v0 + v));
      },
      kRowsPerTask);
}

// dst(u, v) = sum_k w_k src(u + k du, v + k dv), zero outside the plane.
template <typename T>
void ConvolvePass(Planes<T>& p, const std::vector<double>& kernel, bool along_rows) {
  const int radius = static_cast<int>(kernel.size() / 2);
  ParallelFor(
      0, p.height,
      [&](std::int64_t row) {
        const int v = static_cast<int>(row);
        T* out = p.Row(p.dst, v);
        std::fill_n(out, p.width, T{});
        for (int k = -radius; k <= radius; ++k) {
          const double w = kernel[static_cast<std::size_t>(k + radius)];
          if (along_rows) {
            const T* in = p.Row(p.src, v);
            const int u0 = std::max(0, -k), u1 = std::min(p.width, p.width - k);
            for (int u = u0; u < u1; ++u) out[u] += w * in[u + k];
          } else if (v + k >= 0 && v + k < p.height) {
            const T* in = p.Row(p.src, v + k);
            for (int u = 0; u < p.width; ++u) out[u] += w * in[u];
          }
        }
      },
      kRowsPerTask);
  p.src.swap(p.dst);
}

// Centred box of odd `width` along rows (running sum per row) or columns (running sums per
// block of columns), zero outside the plane.
template <typename T>
void BoxPass(Planes<T>& p, int width, bool along_rows) {
  const int half = width / 2;
  const double scale = 1.0 / width;
  if (along_rows) {
    ParallelFor(
        0, p.height,
        [&](std::int64_t row) {
          const T* in = p.Row(p.src, static_cast<int>(row));
          T* out = p.Row(p.dst, static_cast<int>(row));
          T sum{};
          for (int u = 0; u < std::min(half, p.width); ++u) sum += in[u];
          for (int u = 0; u < p.width; ++u) {
            if (u + half < p.width) sum += in[u + half];
            if (u - half - 1 >= 0) sum -= in[u - half - 1];
            out[u] = scale * sum;
          }
        },
        kRowsPerTask);
  } else {
    constexpr int kBlock = 64;
    ParallelFor(0, (p.width + kBlock - 1) / kBlock, [&](std::int64_t block) {
      const int c0 = static_cast<int>(block) * kBlock, c1 = std::min(p.width, c0 + kBlock);
      std::array<T, kBlock> sum{};
      for (int v = 0; v < std::min(half, p.height); ++v) {
        for (int u = c0; u < c1; ++u) sum[static_cast<std::size_t>(u - c0)] += p.Row(p.src, v)[u];
      }
      for (int v = 0; v < p.height; ++v) {
        const T* add = v + half < p.height ? p.Row(p.src, v + half) : nullptr;
        const T* sub = v - half - 1 >= 0 ? p.Row(p.src, v - half - 1) : nullptr;
        T* out = p.Row(p.dst, v);
        for (int u = c0; u < c1; ++u) {
          T& s = sum[static_cast<std::size_t>(u - c0)];
          if (add != nullptr) s += add[u];
          if (sub != nullptr) s -= sub[u];
          out[u] = scale * s;
        }
      }
    });
  }
  p.src.swap(p.dst);
}

template <typename T>
void GaussianBlurImpl(Image<T>& image, const PixelRect& rect, double sigma_px) {
  Require(sigma_px > 0.0, "GaussianBlur: sigma must be > 0");
  const std::vector<double> kernel = GaussianKernel(sigma_px);
  Planes<T>& planes = LoadPlanes(image, rect);
  ConvolvePass(planes, kernel, true);
  ConvolvePass(planes, kernel, false);
  StorePlanes(planes, image, rect);
}

}  // namespace

void GaussianBlur(Image<double>& image, const PixelRect& rect, double sigma_px) {
  GaussianBlurImpl(image, rect, sigma_px);
}

void GaussianBlur(Image<std::complex<double>>& image, const PixelRect& rect, double sigma_px) {
  GaussianBlurImpl(image, rect, sigma_px);
}

void BoxGaussianBlur(Image<std::complex<double>>& image, const PixelRect& rect, double sigma_px) {
  Require(sigma_px >= 1.0, "BoxGaussianBlur: sigma must be >= 1 px");
  Planes<std::complex<double>>& planes = LoadPlanes(image, rect);
  for (const bool along_rows : {true, false}) {
    for (const int width : BoxWidths(sigma_px)) BoxPass(planes, width, along_rows);
  }
  StorePlanes(planes, image, rect);
}

double GaussianNoiseGain(double sigma_px) {
  double sum = 0.0;
  for (const double w : GaussianKernel(sigma_px)) sum += w * w;
  return sum;
}

}  // namespace tofnav::sim
