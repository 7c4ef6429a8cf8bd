// SPDX-License-Identifier: BSD-3-Clause
// Sphere and disc centre geometry against exact ray-sphere intersections.
#include "tofnav/markers/marker_centre.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace tofnav {
namespace {

constexpr double kExactMm = 1e-9;  // closed forms: rounding only
// Near the silhouette the square root amplifies rounding (sqrt of a difference of ~1e5 mm^2).
constexpr double kGrazingMm = 1e-6;

// Range along a unit ray at angle a from the centre direction to a sphere (R, r): the near root.
double RaySphereRangeMm(double centre_range_mm, double angle_rad, double radius_mm) {
  const double b = centre_range_mm * std::cos(angle_rad);
  const double c = centre_range_mm * centre_range_mm - radius_mm * radius_mm;
  return b - std::sqrt(b * b - c);
}

TEST(MarkerCentreRangeMm, RecoversTheSphereCentreFromAnyRayThatHitsIt) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> range(200.0, 900.0), radius(0.0, 8.0), unit(0.0, 0.99);
  for (int i = 0; i < 200; ++i) {
    const double big_r = range(rng), r = radius(rng);
    const double angle = unit(rng) * std::asin(r / big_r);  // inside the silhouette cone
    const double t = RaySphereRangeMm(big_r, angle, r);
    EXPECT_NEAR(MarkerCentreRangeMm(t, angle, r), big_r, kGrazingMm);
    EXPECT_NEAR(MarkerSurfaceRangeMm(big_r, angle, r), t, kGrazingMm);
  }
}

TEST(MarkerCentreRangeMm, FlatDiscIsTheFaceOnPlaneAndGrazingRaysClampToTheSilhouette) {
  EXPECT_NEAR(MarkerCentreRangeMm(400.0 / std::cos(0.01), 0.01, 0.0), 400.0, kExactMm);
  EXPECT_DOUBLE_EQ(MarkerCentreRangeMm(400.0, 0.0, 5.0), 405.0);
  // A mixed pixel outside the silhouette (sin a * t > r) gives the tangent range, not NaN.
  const double outside = MarkerCentreRangeMm(400.0, 0.05, 5.0);
  EXPECT_TRUE(std::isfinite(outside));
  EXPECT_NEAR(outside, 400.0 * std::cos(0.05), kExactMm);
}

TEST(MarkerCentre, PlacesTheCentreOnTheRayAtTheCorrectedRange) {
  DetectedMarker m;  // no core samples: a face-on point at the surface range
  m.ray_in_ahat = Eigen::Vector3d(0.1, -0.2, 1.0).normalized();
  m.surface_range_mm = 500.0;
  EXPECT_NEAR((MarkerCentre(m, 6.0) - m.ray_in_ahat * 506.0).norm(), 0.0, kExactMm);
  EXPECT_NEAR((MarkerCentre(m, 6.0, 497.5) - m.ray_in_ahat * 503.5).norm(), 0.0, kExactMm);
  const DetectedMarker list[] = {m, m};
  const Points3d centres = MarkerCentres(list, 0.0);
  ASSERT_EQ(centres.size(), 2u);
  EXPECT_NEAR((centres[1] - m.ray_in_ahat * 500.0).norm(), 0.0, kExactMm);
}

TEST(CentreRangeMm, IsExactOnSphereSamplesAndIgnoresAnOutlierAtEachEnd) {
  constexpr double kFloatMm = 1e-3;  // samples are stored as float (~3e-5 relative)
  constexpr double kCentreMm = 512.0, kRadiusMm = 5.75;
  DetectedMarker m;
  for (int i = 0; i < 12; ++i) {
    const double angle = 0.0008 * i;  // up to 0.75 r off the centre line
    m.core.push_back({static_cast<float>(RaySphereRangeMm(kCentreMm, angle, kRadiusMm)),
                      static_cast<float>(angle)});
  }
  m.core[3].range_mm += 40.0f;  // a mixed pixel behind
  m.core[7].range_mm -= 25.0f;  // and one in front
  std::vector<double> ranges;
  for (const CoreSample& s : m.core) ranges.push_back(s.range_mm);
  m.surface_range_mm = TrimmedMean(ranges);
  EXPECT_NEAR(CentreRangeMm(m, kRadiusMm, m.surface_range_mm), kCentreMm, kFloatMm);
  EXPECT_NEAR(CentreRangeMm(m, kRadiusMm, m.surface_range_mm - 2.0), kCentreMm - 2.0, 0.01);
  const double surface = SurfaceRangeForCentreMm(m, kRadiusMm, kCentreMm - 3.0);
  EXPECT_NEAR(CentreRangeMm(m, kRadiusMm, surface), kCentreMm - 3.0, 1e-6);
}

TEST(TrimmedMean, DropsAnEighthAtEachEnd) {
  std::vector<double> v = {9.0, 1.0, 2.0, 100.0, 3.0, 4.0, -50.0};  // drops 1 at each end
  EXPECT_DOUBLE_EQ(TrimmedMean(v), 3.8);
  std::vector<double> sixteen = {-90.0, 80.0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, -70.0, 60.0};
  EXPECT_DOUBLE_EQ(TrimmedMean(sixteen), 6.5);     // drops 2 at each end
  std::vector<double> three = {5.0, 1.0, 1000.0};  // the median
  EXPECT_DOUBLE_EQ(TrimmedMean(three), 5.0);
  std::vector<double> two = {1.0, 2.0};
  EXPECT_DOUBLE_EQ(TrimmedMean(two), 1.5);
  std::vector<double> empty;
  EXPECT_THROW(TrimmedMean(empty), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
