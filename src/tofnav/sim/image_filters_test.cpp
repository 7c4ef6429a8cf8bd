// SPDX-License-Identifier: BSD-3-Clause
// Separable Gaussian filters: energy, width, phase, and the white-noise gain.
#include "tofnav/sim/image_filters.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace tofnav::sim {
namespace {

struct Moments {
  double sum = 0.0;
  double variance_px2 = 0.0;  // along u
};

template <typename T>
Moments DeltaMoments(const Image<T>& image, int centre) {
  Moments m;
  for (int v = 0; v < image.height(); ++v) {
    for (int u = 0; u < image.width(); ++u) {
      const double w = std::abs(image(u, v));
      m.sum += w;
      m.variance_px2 += w * (u - centre) * (u - centre);
    }
  }
  m.variance_px2 /= m.sum;
  return m;
}

TEST(GaussianBlur, KeepsEnergyAndHasTheRequestedWidth) {
  constexpr int kSize = 64, kCentre = 32;
  constexpr double kSigma = 1.5;
  Image<double> image(kSize, kSize, 0.0);
  image(kCentre, kCentre) = 1.0;
  GaussianBlur(image, {0, 0, kSize, kSize}, kSigma);
  const Moments m = DeltaMoments(image, kCentre);
  EXPECT_NEAR(m.sum, 1.0, 1e-12);
  EXPECT_NEAR(m.variance_px2, kSigma * kSigma, 0.02);  // kernel truncated at 3 sigma
}

TEST(BoxGaussianBlur, ApproximatesAWideGaussian) {
  constexpr int kSize = 256, kCentre = 128;
  constexpr double kSigma = 30.0;
  Image<std::complex<double>> image(kSize, kSize);
  image(kCentre, kCentre) = std::polar(1.0, 0.7);
  BoxGaussianBlur(image, {0, 0, kSize, kSize}, kSigma);
  const Moments m = DeltaMoments(image, kCentre);
  EXPECT_NEAR(m.sum, 1.0, 1e-9);
  EXPECT_NEAR(std::sqrt(m.variance_px2), kSigma, 0.05 * kSigma);         // integer box widths
  EXPECT_NEAR(std::arg(image(kCentre + 20, kCentre - 10)), 0.7, 1e-12);  // phase untouched
}

TEST(GaussianBlur, LeavesPixelsOutsideTheRectAlone) {
  Image<double> image(16, 16, 1.0);
  GaussianBlur(image, {4, 4, 8, 8}, 1.0);
  EXPECT_EQ(image(0, 0), 1.0);
  EXPECT_EQ(image(15, 3), 1.0);
  EXPECT_LT(image(4, 4), 1.0);  // zero padding at the rect border
  EXPECT_NEAR(image(8, 8), 1.0, 1e-3);
}

TEST(GaussianNoiseGain, PredictsTheStdOfBlurredWhiteNoise) {
  constexpr int kSize = 200;
  constexpr double kSigma = 0.7;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  Image<double> noise(kSize, kSize);
  for (double& n : noise.pixels()) n = normal(rng);
  GaussianBlur(noise, {0, 0, kSize, kSize}, kSigma);
  double sum2 = 0.0;
  int count = 0;
  for (int v = 5; v < kSize - 5; ++v) {
    for (int u = 5; u < kSize - 5; ++u, ++count) sum2 += noise(u, v) * noise(u, v);
  }
  EXPECT_NEAR(std::sqrt(sum2 / count), GaussianNoiseGain(kSigma), 0.03 * GaussianNoiseGain(kSigma));
}

}  // namespace
}  // namespace tofnav::sim
