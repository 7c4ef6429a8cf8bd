// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/sensor/ahat_camera.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr double kRangeMm = 500.0;
constexpr double kRoundTripTolPx = 0.01;  // brief: Project inverts Ray to 0.01 px
constexpr double kPlaneTolMm = 1e-3;      // float rays: ~1e-7 relative error at <= 1 m range
// s = 0 and s = 0.5 tables of one model agree to float precision once resampled (cubic) ...
constexpr double kSameOffsetTolMm = 1e-3;
// ... except within a few px of the fold, whose kink no interpolation reproduces (a sample
// straddling it misses the peak by up to 0.5 px, ~1 mm at 500 mm).
constexpr double kFoldKinkPx = 3.0;
// A wrong offset shifts every ray by (0.5, 0.5) px: 2.8 mrad, 1.4 mm at 500 mm at the centre,
// and no less than ~0.7 mm anywhere (tangential pixels subtend sin(theta) / r rad).
constexpr double kWrongOffsetMinMm = 0.5;
constexpr double kWrongOffsetCentreTolMm = 0.02;  // the centre pixel is not exactly at the pp
constexpr double kPrincipalPointTolPx = 1e-3;     // x, y are odd around it: interpolation exact
constexpr double kFovTolRad = 2.0 * std::numbers::pi / 180.0;  // brief: within 2 degrees
constexpr double kMeasuredFovRad = 118.3 * std::numbers::pi / 180.0;
constexpr double kMinEquidistantFovRad = 115.0 * std::numbers::pi / 180.0;  // 511 px / 254 px

SyntheticAhatOptions Realistic(double sample_offset_px) {
  SyntheticAhatOptions options;
  options.focal_px = 255.9;  // docs/ahat.md section 10 fit: theta = r / 255.9 + 1.71e-9 r^3
  options.cubic_rad_per_px3 = 1.71e-9;
  options.aspect_y = 0.9986;
  options.sample_offset_px = sample_offset_px;
  return options;
}

// Shared fixtures: building a table and a camera takes ~0.2 s each unoptimised.
const AhatCamera& DefaultCamera() {
  static const AhatCamera camera(MakeSyntheticAhatCalibration());
  return camera;
}
const AhatCalibration& RealisticCalibration(double sample_offset_px) {
  if (sample_offset_px == 0.0) {
    static const AhatCalibration integer = MakeSyntheticAhatCalibration(Realistic(0.0));
    return integer;
  }
  static const AhatCalibration half = MakeSyntheticAhatCalibration(Realistic(0.5));
  return half;
}
const AhatCamera& RealisticCamera(double sample_offset_px) {
  if (sample_offset_px == 0.0) {
    static const AhatCamera integer(RealisticCalibration(0.0));
    return integer;
  }
  static const AhatCamera half(RealisticCalibration(0.5));
  return half;
}

/// A sub-pixel grid over the whole image plus a dense grid around every pixel on the mask edge.
std::vector<Eigen::Vector2d> SamplePositions(const AhatCamera& camera) {
  std::vector<Eigen::Vector2d> positions;
  constexpr double kCoarseStepPx = 2.37;  // irrational-ish: hits all sub-pixel phases
  for (double v = 0.11; v < camera.height(); v += kCoarseStepPx) {
    for (double u = 0.07; u < camera.width(); u += kCoarseStepPx) positions.emplace_back(u, v);
  }
  for (int v = 1; v + 1 < camera.height(); ++v) {
    for (int u = 1; u + 1 < camera.width(); ++u) {
      if (!camera.IsValid(u, v) || (camera.IsValid(u - 1, v) && camera.IsValid(u + 1, v) &&
                                    camera.IsValid(u, v - 1) && camera.IsValid(u, v + 1))) {
        continue;
      }
      for (const double dv : {-0.75, -0.25, 0.25, 0.75}) {
        for (const double du : {-0.75, -0.25, 0.25, 0.75}) positions.emplace_back(u + du, v + dv);
      }
      positions.emplace_back(u, v);
    }
  }
  return positions;
}

void ExpectRoundTrip(const AhatCamera& camera) {
  int tested = 0;
  double worst_px = 0.0;
  for (const Eigen::Vector2d& pixel : SamplePositions(camera)) {
    const std::optional<Eigen::Vector3d> ray = camera.Ray(pixel);
    if (!ray) continue;
    const std::optional<Eigen::Vector2d> projected = camera.Project(kRangeMm * *ray);
    ASSERT_TRUE(projected.has_value()) << "pixel " << pixel.transpose();
    worst_px = std::max(worst_px, (*projected - pixel).norm());
    ++tested;
  }
  EXPECT_LT(worst_px, kRoundTripTolPx);
  EXPECT_GT(tested, 40000);  // ~37k of the coarse grid (80% of the image) plus the edge band
}

TEST(AhatCamera, RoundTripEquidistant) { ExpectRoundTrip(DefaultCamera()); }

TEST(AhatCamera, RoundTripRealisticSampledAtIntegers) { ExpectRoundTrip(RealisticCamera(0.0)); }

/// theta(r) of the synthetic equidistant model, fold included (docs/ahat.md section 11).
double ModelThetaRad(double r_px, const SyntheticAhatOptions& options) {
  return r_px <= options.fold_radius_px ? r_px / options.focal_px
                                        : (2.0 * options.fold_radius_px - r_px) / options.focal_px;
}

TEST(AhatCamera, RangeAlongRaysRecoversPlane) {
  const SyntheticAhatOptions options;  // s = c = 0.5: table entries are our pixel centres
  const AhatCamera& camera = DefaultCamera();
  int tested = 0;
  double worst_z_mm = 0.0;
  double worst_lateral_mm = 0.0;
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      if (!camera.IsValid(u, v)) continue;
      const double du = u - options.principal_point_px.x();
      const double dv = v - options.principal_point_px.y();
      const double r_px = std::sqrt(du * du + dv * dv);
      const double theta_rad = ModelThetaRad(r_px, options);
      const double range_mm = kRangeMm / std::cos(theta_rad);  // plane z = 500 mm
      const Eigen::Vector3d point = camera.PointFromRange(u, v, range_mm);
      // Analytic point on the plane: azimuth kept, lateral distance 500 tan(theta).
      const double lateral_mm = r_px > 0.0 ? kRangeMm * std::tan(theta_rad) / r_px : 0.0;
      worst_z_mm = std::max(worst_z_mm, std::abs(point.z() - kRangeMm));
      worst_lateral_mm = std::max(
          worst_lateral_mm, std::hypot(point.x() - lateral_mm * du, point.y() - lateral_mm * dv));
      ++tested;
    }
  }
  EXPECT_GT(tested, 200000);
  EXPECT_LT(worst_z_mm, kPlaneTolMm);
  EXPECT_LT(worst_lateral_mm, kPlaneTolMm);
  EXPECT_EQ(camera.PointFromRange(0, 0, kRangeMm), Eigen::Vector3d::Zero());  // invalid corner
  EXPECT_THROW(camera.PointFromRange(512, 0, kRangeMm), PreconditionError);
}

TEST(AhatCamera, SampleOffsetOfTheFileIsHonoured) {
  const SyntheticAhatOptions options = Realistic(0.5);
  const AhatCamera& half_camera = RealisticCamera(0.5);
  const AhatCamera& integer_camera = RealisticCamera(0.0);
  AhatCalibration wrong = RealisticCalibration(0.0);
  wrong.sample_offset_px = 0.5;  // the trap of docs/ahat.md section 5.3
  const AhatCamera wrong_camera(wrong);
  double worst_same_mm = 0.0;
  double wrong_min_mm = std::numeric_limits<double>::infinity();
  int compared = 0;
  for (int v = 0; v < half_camera.height(); v += 2) {  // every other pixel: fast unoptimised
    for (int u = 0; u < half_camera.width(); u += 2) {
      const double r_px = (Eigen::Vector2d(u, v) - options.principal_point_px).norm();
      if (r_px > options.fold_radius_px - kFoldKinkPx || !half_camera.IsValid(u, v) ||
          !integer_camera.IsValid(u, v) || !wrong_camera.IsValid(u, v)) {
        continue;  // s = 0 also loses the last column and row (no entry beyond them)
      }
      const Eigen::Vector3d truth = half_camera.PointFromRange(u, v, kRangeMm);
      worst_same_mm =
          std::max(worst_same_mm, (integer_camera.PointFromRange(u, v, kRangeMm) - truth).norm());
      wrong_min_mm =
          std::min(wrong_min_mm, (wrong_camera.PointFromRange(u, v, kRangeMm) - truth).norm());
      ++compared;
    }
  }
  EXPECT_GT(compared, 50000);
  EXPECT_LT(worst_same_mm, kSameOffsetTolMm);
  EXPECT_GT(wrong_min_mm, kWrongOffsetMinMm);
  const Eigen::Vector2i centre = half_camera.principal_point_px().array().round().cast<int>();
  const double wrong_centre_mm = (wrong_camera.PointFromRange(centre.x(), centre.y(), kRangeMm) -
                                  half_camera.PointFromRange(centre.x(), centre.y(), kRangeMm))
                                     .norm();
  // (0.5, 0.5) px at the centre scale 1 / f rad per px.
  EXPECT_NEAR(wrong_centre_mm, std::hypot(0.5, 0.5) / options.focal_px * kRangeMm,
              kWrongOffsetCentreTolMm);
  RecordProperty("same_offset_worst_mm", std::to_string(worst_same_mm));
  RecordProperty("wrong_offset_min_mm", std::to_string(wrong_min_mm));
  RecordProperty("wrong_offset_centre_mm", std::to_string(wrong_centre_mm));
}

TEST(AhatCamera, PrincipalPointComesFromTheTable) {
  for (const double s : {0.0, 0.5}) {
    const SyntheticAhatOptions options = Realistic(s);
    const AhatCamera& camera = RealisticCamera(s);
    EXPECT_LT((camera.principal_point_px() - options.principal_point_px).norm(),
              kPrincipalPointTolPx)
        << "s = " << s;
  }
}

TEST(AhatCamera, FieldOfViewAcrossTheCentreRow) {
  for (const bool realistic : {false, true}) {
    const SyntheticAhatOptions options = realistic ? Realistic(0.5) : SyntheticAhatOptions{};
    const AhatCamera& camera = realistic ? RealisticCamera(0.5) : DefaultCamera();
    const int row = static_cast<int>(std::lround(camera.principal_point_px().y()));
    int left = 0;
    int right = camera.width() - 1;
    while (left < right && !camera.IsValid(left, row)) ++left;
    while (right > left && !camera.IsValid(right, row)) --right;
    const double fov_rad = std::acos(
        camera.PixelRay(left, row).cast<double>().dot(camera.PixelRay(right, row).cast<double>()));
    if (realistic) {
      EXPECT_NEAR(fov_rad, kMeasuredFovRad, kFovTolRad);  // docs/ahat.md section 10: 118.3 degrees
    } else {
      const double cx = options.principal_point_px.x();
      EXPECT_NEAR(fov_rad, (right - cx) / options.focal_px + (cx - left) / options.focal_px,
                  kFovTolRad);
      EXPECT_GT(fov_rad, kMinEquidistantFovRad);
    }
  }
}

}  // namespace
}  // namespace tofnav
