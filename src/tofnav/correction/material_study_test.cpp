// SPDX-License-Identifier: BSD-3-Clause
// The material study on a synthetic reference plane with known per-material biases.
#include "tofnav/correction/material_study.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

namespace tofnav {
namespace {

// 0.5 mm range noise on 600 reference points and 400 sample points: the plane's offset and the
// median of a bias come out within a few hundredths of a millimetre.
constexpr double kNoiseMm = 0.5;
constexpr double kBiasTolMm = 0.1;      // recovered median bias vs the bias put in
constexpr double kPlaneTolMm = 0.1;     // plane offset vs truth
constexpr double kNormalTolRad = 2e-3;  // plane normal vs truth
constexpr double kExactTolMm = 1e-9;    // noise-free algebra
constexpr double kAngleTolRad = 1e-9;

struct Scene {
  Eigen::Vector3d normal = Eigen::Vector3d(std::sin(0.5), 0.0, -std::cos(0.5));  // 28.6 deg
  double offset_mm = 450.0;  // n . x + D = 0 with n facing the camera: the plane at z ~ 514 mm
  // The plane point on the ray through pixel-like direction (x, y, 1).
  Eigen::Vector3d OnPlane(double x, double y) const {
    const Eigen::Vector3d ray = Eigen::Vector3d(x, y, 1.0).normalized();
    return ray * (-offset_mm / normal.dot(ray));
  }
};

// A point moved along its ray by `bias_mm` (measured farther for bias > 0).
Eigen::Vector3d AlongRay(const Eigen::Vector3d& p, double bias_mm) {
  return p * (1.0 + bias_mm / p.norm());
}

// 600 noisy tape points; every `outlier_every`-th one 25 mm behind (a mixed pixel), 0 = none.
std::vector<Eigen::Vector3d> TapePoints(const Scene& scene, std::mt19937_64& rng,
                                        int outlier_every) {
  std::normal_distribution<double> noise(0.0, kNoiseMm);
  std::uniform_real_distribution<double> xy(-0.25, 0.25);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 600; ++i) {
    const double outlier_mm = outlier_every > 0 && i % outlier_every == 0 ? 25.0 : 0.0;
    points.push_back(AlongRay(scene.OnPlane(xy(rng), xy(rng)), noise(rng) + outlier_mm));
  }
  return points;
}

TEST(ReferenceDepthError, IsTheRangeOffsetAlongTheRay) {
  const Scene scene;
  const ReferencePlane plane{scene.normal, scene.offset_mm, 0.0, 0};
  for (const double bias : {-4.0, 0.0, 2.5, 14.0}) {
    const Eigen::Vector3d p = scene.OnPlane(0.2, -0.1);
    const std::optional<double> e = ReferenceDepthErrorMm(plane, AlongRay(p, bias));
    ASSERT_TRUE(e.has_value());
    EXPECT_NEAR(*e, bias, kExactTolMm);
  }
  const Eigen::Vector3d p = scene.OnPlane(0.0, 0.0);
  EXPECT_NEAR(PlaneIncidenceRad(plane, p), 0.5, kAngleTolRad);
  // A ray in the plane has no intersection.
  const Eigen::Vector3d along = Eigen::Vector3d::UnitZ().cross(scene.normal).normalized();
  EXPECT_FALSE(ReferenceDepthErrorMm(plane, along * 500.0).has_value());
}

TEST(FitReferencePlane, RecoversThePlaneDespiteNoiseAndOutliers) {
  const Scene scene;
  std::mt19937_64 rng(7);
  const std::vector<Eigen::Vector3d> points = TapePoints(scene, rng, 10);
  const std::optional<ReferencePlane> plane = FitReferencePlane(points);
  ASSERT_TRUE(plane.has_value());
  EXPECT_NEAR(plane->offset_mm, scene.offset_mm, kPlaneTolMm);
  EXPECT_LT(std::acos(std::min(1.0, plane->normal.dot(scene.normal))), kNormalTolRad);
  EXPECT_LE(plane->inliers, 540 + 10);  // the outliers are gone (a few noise tails may go too)
  EXPECT_FALSE(FitReferencePlane(std::span(points).first(10)).has_value());
}

TEST(MaterialStudy, RecoversPerMaterialBiasesPerBin) {
  const Scene scene;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, kNoiseMm);
  std::uniform_real_distribution<double> xy(-0.3, 0.3);
  const std::optional<ReferencePlane> plane = FitReferencePlane(TapePoints(scene, rng, 0));
  ASSERT_TRUE(plane.has_value());
  const double bias_mm[2] = {3.0, 12.0};  // e.g. nylon, PLA
  MaterialStudyOptions options;
  options.depth_bin_mm = 100.0;
  MaterialStudy study({"nylon", "pla"}, options);
  for (int i = 0; i < 400; ++i) {
    const int material = i % 2;
    const Eigen::Vector3d truth = scene.OnPlane(xy(rng), xy(rng));
    const Eigen::Vector3d measured = AlongRay(truth, bias_mm[material] + noise(rng));
    const std::optional<double> e = ReferenceDepthErrorMm(*plane, measured);
    ASSERT_TRUE(e.has_value());
    study.Add({material, static_cast<float>(truth.norm()),
               static_cast<float>(PlaneIncidenceRad(*plane, measured)), static_cast<float>(*e),
               static_cast<float>(measured.norm() - truth.norm())});
  }
  const MaterialStudyResult result = study.Summarise();
  ASSERT_EQ(result.overall.size(), 2u);
  for (const MaterialCell& cell : result.overall) {
    EXPECT_EQ(cell.vs_reference_mm.count, 200u);
    EXPECT_NEAR(cell.vs_reference_mm.median, bias_mm[cell.material], kBiasTolMm);
    EXPECT_NEAR(cell.vs_truth_mm.median, bias_mm[cell.material], kBiasTolMm);
    EXPECT_NEAR(cell.vs_reference_mm.sd, kNoiseMm, kBiasTolMm);
  }
  std::size_t binned = 0;
  for (const MaterialCell& cell : result.by_depth) {
    binned += cell.vs_reference_mm.count;
    EXPECT_DOUBLE_EQ(cell.depth_max_mm - cell.depth_min_mm, 100.0);
  }
  EXPECT_EQ(binned, 400u);
  for (const MaterialCell& cell : result.by_angle) {  // the ray angles lie within 15-45 deg
    EXPECT_GE(cell.angle_min_rad, 0.0);
    EXPECT_LE(cell.angle_max_rad, 50.0 * std::numbers::pi / 180.0 + 1e-9);
  }
  EXPECT_THROW(study.Add({2, 500.0f, 0.1f, 0.0f, 0.0f}), std::invalid_argument);
}

TEST(SummariseDepthErrors, QuartilesMeanAndStdSkippingNaN) {
  const Summary s = SummariseDepthErrors({1.0f, 2.0f, 3.0f, 4.0f, 5.0f, NAN});
  EXPECT_EQ(s.count, 5u);
  EXPECT_DOUBLE_EQ(s.median, 3.0);
  EXPECT_DOUBLE_EQ(s.p25, 2.0);
  EXPECT_DOUBLE_EQ(s.p75, 4.0);
  EXPECT_DOUBLE_EQ(s.mean, 3.0);
  EXPECT_NEAR(s.sd, std::sqrt(2.5), 1e-12);
  EXPECT_EQ(SummariseDepthErrors({}).count, 0u);
}

}  // namespace
}  // namespace tofnav
