// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/core/distance_transform.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

// Squared distances are sums of products of the spacings: exact up to double round-off.
constexpr double kSquaredTolMm2 = 1e-9;

TEST(SquaredDistanceTransform, AnisotropicMatchesBruteForce) {
  const std::array<int, 3> dims = {7, 5, 6};
  const std::array<double, 3> spacing = {0.5, 1.25, 2.0};
  const std::array<std::array<int, 3>, 3> features = {{{1, 1, 1}, {6, 4, 0}, {3, 0, 5}}};
  std::vector<double> d2(7 * 5 * 6, std::numeric_limits<double>::infinity());
  for (const auto& f : features) d2[static_cast<std::size_t>(f[0] + 7 * (f[1] + 5 * f[2]))] = 0.0;
  SquaredDistanceTransform(d2, dims, spacing);
  for (int k = 0; k < 6; ++k) {
    for (int j = 0; j < 5; ++j) {
      for (int i = 0; i < 7; ++i) {
        double best = std::numeric_limits<double>::infinity();
        for (const auto& f : features) {
          const double dx = (i - f[0]) * spacing[0], dy = (j - f[1]) * spacing[1],
                       dz = (k - f[2]) * spacing[2];
          best = std::min(best, dx * dx + dy * dy + dz * dz);
        }
        EXPECT_NEAR(d2[static_cast<std::size_t>(i + 7 * (j + 5 * k))], best, kSquaredTolMm2);
      }
    }
  }
}

TEST(SquaredDistanceTransform, NoFeatureStaysInfiniteAndBadInputThrows) {
  std::vector<double> d2(8, std::numeric_limits<double>::infinity());
  SquaredDistanceTransform(d2, {2, 2, 2}, {1.0, 1.0, 1.0});
  for (const double v : d2) EXPECT_TRUE(std::isinf(v));
  EXPECT_THROW(SquaredDistanceTransform(d2, {2, 2, 3}, {1.0, 1.0, 1.0}), PreconditionError);
  EXPECT_THROW(SquaredDistanceTransform(d2, {2, 2, 2}, {1.0, 0.0, 1.0}), PreconditionError);
}

}  // namespace
}  // namespace tofnav
