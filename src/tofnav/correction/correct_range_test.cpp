// SPDX-License-Identifier: BSD-3-Clause
// Segmentation and whole-frame correction on synthetic planes with a known linear bias.
#include "tofnav/correction/correct_range.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "correction_test_scenes.hpp"

namespace tofnav {
namespace {

using testing::CorrectionCamera;

DepthErrorModel KnownModel() {
  DepthErrorModel model;
  model.c1_mm = 3.0;
  model.c2 = 0.01;
  model.c3_mm = 4.0;
  return model;
}

// A plane tilted 0.4 rad at 450 mm with the model's bias, and a bright 9 x 9 px "marker" patch
// at (300, 260) measured without bias.
AhatFrame BiasedPlaneFrame(const DepthErrorModel& model, Image<float>& truth) {
  const testing::TestPlane plane = testing::TiltedPlane(450.0, 0.4);
  AhatFrame frame = testing::SyntheticFrame(
      [&](int, int, const Eigen::Vector3d& ray) { return plane.Range(ray); },
      [&](double d, int u, int v) {
        const bool marker = std::abs(u - 300) <= 4 && std::abs(v - 260) <= 4;
        const Eigen::Vector3d ray = CorrectionCamera().PixelRay(u, v).cast<double>();
        return marker ? d : d + model.BiasMm(d, plane.Incidence(ray));
      },
      200, &truth, 180, 340);
  for (int v = 256; v <= 264; ++v) {
    for (int u = 296; u <= 304; ++u) frame.ab(u, v) = 5000;
  }
  return frame;
}

TEST(SegmentFrame, MarkerTransitionAndHeadAreas) {
  Image<float> truth;
  const AhatFrame frame = BiasedPlaneFrame(KnownModel(), truth);
  SegmentationOptions options;
  options.roi_radius_mm = 60.0;
  options.head_region.enabled = false;  // a plane: the automatic head region would drop it
  const FrameSegmentation seg = SegmentFrame(frame, CorrectionCamera(), options);
  ASSERT_EQ(seg.markers.size(), 1u);
  EXPECT_EQ(seg.markers[0].pixels.size(), 81u);
  EXPECT_EQ(seg.labels(300, 260), static_cast<std::uint8_t>(PixelClass::kMarker));
  EXPECT_EQ(seg.labels(307, 260), static_cast<std::uint8_t>(PixelClass::kTransition));
  EXPECT_EQ(seg.labels(308, 260), static_cast<std::uint8_t>(PixelClass::kHead));
  EXPECT_EQ(seg.labels(190, 260), static_cast<std::uint8_t>(PixelClass::kOutside));  // ROI
  EXPECT_GT(seg.head_pixels, 1000);
}

TEST(CorrectRangeImage, UndoesAKnownLinearBias) {
  // Ranges are rounded to 1 mm before correction (+-0.5 mm), normals come from the rounded range.
  constexpr double kMeanTolMm = 0.05;  // rounding averages out over many pixels
  constexpr double kMaxTolMm = 1.0;    // 0.5 rounding + C3 x theta error of rounded-range normals
  const DepthErrorModel model = KnownModel();
  Image<float> truth;
  const AhatFrame frame = BiasedPlaneFrame(model, truth);
  CorrectRangeOptions options;
  options.segmentation.head_region.enabled = false;  // a plane is the surface here
  const CorrectedFrame corrected = CorrectFrame(frame, CorrectionCamera(), model, options);
  double sum = 0.0, worst = 0.0;
  int count = 0;
  for (int v = 200; v <= 320; ++v) {
    for (int u = 200; u <= 320; ++u) {
      const auto label = static_cast<PixelClass>(corrected.segmentation.labels(u, v));
      if (label == PixelClass::kTransition) {
        EXPECT_EQ(corrected.range_mm(u, v), 0.0f);
        continue;
      }
      if (corrected.range_mm(u, v) <= 0.0f) continue;
      const double e = corrected.range_mm(u, v) - truth(u, v);
      sum += e;
      worst = std::max(worst, std::abs(e));
      ++count;
    }
  }
  ASSERT_GT(count, 10000);
  EXPECT_NEAR(sum / count, 0.0, kMeanTolMm);
  EXPECT_LT(worst, kMaxTolMm);
  // The marker is unbiased and f_rf is empty: kept as measured.
  EXPECT_EQ(corrected.range_mm(300, 260), static_cast<float>(frame.range_mm(300, 260)));
}

TEST(CorrectRangeImage, DropsSurfacePixelsSeenBeyondTheMaximumIncidence) {
  const DepthErrorModel model = KnownModel();
  Image<float> truth;
  const AhatFrame frame = BiasedPlaneFrame(model, truth);
  CorrectRangeOptions options;
  options.segmentation.head_region.enabled = false;
  const CorrectedFrame all = CorrectFrame(frame, CorrectionCamera(), model, options);
  options.max_incidence_rad = 0.35;  // the plane is tilted 0.4 rad: most of it is seen beyond
  const CorrectedFrame steep = CorrectFrame(frame, CorrectionCamera(), model, options);
  int kept = 0, dropped = 0;
  for (int v = 200; v <= 320; ++v) {
    for (int u = 200; u <= 320; ++u) {
      if (all.range_mm(u, v) <= 0.0f) continue;
      const auto label = static_cast<PixelClass>(all.segmentation.labels(u, v));
      const float theta = all.normals.incidence_rad(u, v);
      if (label == PixelClass::kMarker || theta <= 0.35f) {
        EXPECT_EQ(steep.range_mm(u, v), all.range_mm(u, v));  // markers keep Eq. (2)
        ++kept;
      } else {
        EXPECT_EQ(steep.range_mm(u, v), 0.0f);
        ++dropped;
      }
    }
  }
  EXPECT_GT(dropped, 1000);
  EXPECT_GT(kept, 81);  // the marker and the pixels seen nearly head-on
}

// A dark surface far away (true AB 12-24 counts) streamed lossily: each pixel's AB scatters by
// 15 % (shot noise) and is then sent as hl2ss's square code c, recovered as c^2. The range carries
// the model's bias at the true AB, intensity term C4 = 2 mm per ln unit.
TEST(CorrectRangeImage, ReadsTheIntensityTermsAbOverTheSurfaceNotPerPixel) {
  // The range error of the AB reading alone (against the same range corrected at the true AB):
  // the window's mean of the codes' interval centres is unbiased to about 0.02 in ln AB (0.04 mm
  // through C4). One pixel's floor c^2 (hl2ss's reading, the default) lies 0.1-0.3 low in ln AB,
  // 0.2-0.6 mm through C4, and scatters by about 0.25 in ln AB; the 7 x 7 window's mean scatters
  // several times less (49 pixels: 7 times, bar the edges).
  constexpr double kWindowMedianTolMm = 0.1;
  constexpr double kFloorMinBiasMm = 0.2;
  constexpr double kScatterRatio = 3.0;
  DepthErrorModel model = KnownModel();
  model.use_intensity = true;
  model.c4_mm = 2.0;
  model.ab_reference = 16.0;
  const testing::TestPlane plane = testing::TiltedPlane(600.0, 0.3);
  const auto true_ab = [](int u) { return 12.0 + 12.0 * (u - 180) / 160.0; };
  AhatFrame frame = testing::SyntheticFrame(
      [&](int, int, const Eigen::Vector3d& ray) { return plane.Range(ray); },
      [&](double d, int u, int v) {
        const Eigen::Vector3d ray = CorrectionCamera().PixelRay(u, v).cast<double>();
        return d + model.BiasMm(d, plane.Incidence(ray), true_ab(u));
      },
      0, nullptr, 180, 340);
  Image<float> truth(frame.range_mm.width(), frame.range_mm.height());
  std::mt19937 rng(7);
  std::normal_distribution<double> shot(0.0, 0.15);
  for (int v = 180; v <= 340; ++v) {
    for (int u = 180; u <= 340; ++u) {
      if (frame.range_mm(u, v) == 0) continue;
      const Eigen::Vector3d ray = CorrectionCamera().PixelRay(u, v).cast<double>();
      truth(u, v) = static_cast<float>(plane.Range(ray));
      const double code = std::floor(std::sqrt(true_ab(u) * std::exp(shot(rng))));
      frame.ab(u, v) = static_cast<std::uint16_t>(code * code);
    }
  }
  struct Errors {
    double median_mm, scatter_mm;  // median and 1.4826 MAD of the AB reading's range error
  };
  frame.ab_lossy = true;
  const auto errors_of = [&](bool window_mean) {
    CorrectRangeOptions options;
    options.segmentation.head_region.enabled = false;  // a plane is the surface here
    options.roi_only = false;
    options.intensity_ab.window_mean = window_mean;
    const CorrectedFrame corrected = CorrectFrame(frame, CorrectionCamera(), model, options);
    std::vector<double> e;
    for (int v = 190; v <= 330; ++v) {
      for (int u = 190; u <= 330; ++u) {
        if (corrected.range_mm(u, v) <= 0.0f || truth(u, v) <= 0.0f) continue;
        // Against the same range corrected at the true AB: the AB reading's error alone.
        e.push_back(corrected.range_mm(u, v) -
                    model.CorrectRangeMm(frame.range_mm(u, v),
                                         corrected.normals.incidence_rad(u, v), true_ab(u)));
      }
    }
    EXPECT_GT(e.size(), 10000u);
    const auto median = [](std::vector<double> x) {
      std::nth_element(x.begin(), x.begin() + x.size() / 2, x.end());
      return x[x.size() / 2];
    };
    const double m = median(e);
    for (double& x : e) x = std::abs(x - m);
    return Errors{m, 1.4826 * median(e)};
  };
  const Errors window = errors_of(true), floor = errors_of(false);
  std::printf(
      "AB reading's range error, median / scatter [mm]: window %+.3f / %.3f, one pixel's floor "
      "%+.3f / %.3f\n",
      window.median_mm, window.scatter_mm, floor.median_mm, floor.scatter_mm);
  EXPECT_LT(std::abs(window.median_mm), kWindowMedianTolMm);
  EXPECT_GT(std::abs(floor.median_mm), kFloorMinBiasMm);
  EXPECT_GT(floor.scatter_mm, kScatterRatio * window.scatter_mm);
}

// KnownModel with the angle term `term` and an intensity term of 0.7 mm per ln unit.
DepthErrorModel WithIntensityTerm(AngleTerm term) {
  DepthErrorModel model = KnownModel();
  model.angle_term = term;
  model.use_intensity = true;
  model.c4_mm = 0.7;
  return model;
}

TEST(DepthErrorModel, OtherReferencesGiveTheSameBias) {
  constexpr double kTolMm = 1e-9;  // exact algebra
  for (const AngleTerm term :
       {AngleTerm::kTheta, AngleTerm::kThetaSquared, AngleTerm::kOneMinusCos}) {
    const DepthErrorModel model = WithIntensityTerm(term);
    const DepthErrorModel moved = model.WithReferences(0.65, 210.0);
    EXPECT_EQ(moved.theta_reference_rad, 0.65);
    EXPECT_EQ(moved.ab_reference, 210.0);
    // C1 is now the bias at the references (and d = 0).
    EXPECT_NEAR(moved.c1_mm, model.BiasMm(0.0, 0.65, 210.0), kTolMm);
    for (const double theta : {0.0, 0.4, 1.2}) {
      for (const double ab : {40.0, 130.0, 900.0}) {
        EXPECT_NEAR(moved.BiasMm(432.0, theta, ab), model.BiasMm(432.0, theta, ab), kTolMm);
      }
    }
    EXPECT_NEAR(moved.WithReferences(0.0, 130.0).c1_mm, model.c1_mm, kTolMm);
  }
  DepthErrorModel bad = KnownModel();
  bad.theta_reference_rad = 2.0;
  EXPECT_THROW(bad.Check(), std::invalid_argument);
}

TEST(DepthErrorModel, CorrectInvertsBias) {
  constexpr double kTolMm = 1e-9;  // exact algebra
  for (const AngleTerm term :
       {AngleTerm::kTheta, AngleTerm::kThetaSquared, AngleTerm::kOneMinusCos}) {
    const DepthErrorModel model = WithIntensityTerm(term);
    const double d = 432.0, theta = 0.7, ab = 90.0;
    EXPECT_NEAR(model.CorrectRangeMm(d + model.BiasMm(d, theta, ab), theta, ab), d, kTolMm);
    EXPECT_EQ(ParseAngleTerm(AngleTermName(term)), term);
  }
  // The sensor's cyclic error is removed before the other terms: the fixed point that inverts
  // d_m = d' + w(d') contracts by |w'| <= 2 pi A / P = 0.018 a step (1 mm at 352 mm).
  constexpr double kCyclicTolMm = 1e-5;
  DepthErrorModel cyclic = KnownModel();
  cyclic.cyclic = {.amplitude_mm = 1.0, .period_mm = 351.7, .phase_rad = 0.4};
  for (const double d : {300.0, 432.0, 611.0}) {
    const double bias = cyclic.BiasMm(d, 0.5, 0.0);
    EXPECT_NEAR(
        bias - KnownModel().BiasMm(d, 0.5, 0.0),
        std::sin(2.0 * std::numbers::pi * (d + KnownModel().BiasMm(d, 0.5, 0.0)) / 351.7 + 0.4),
        1e-12);
    EXPECT_NEAR(cyclic.CorrectRangeMm(d + bias, 0.5, 0.0), d, kCyclicTolMm);
  }
  DepthErrorModel bad_cyclic = KnownModel();
  bad_cyclic.cyclic = {.amplitude_mm = 1.0, .period_mm = 0.0, .phase_rad = 0.0};
  EXPECT_THROW(bad_cyclic.Check(), std::invalid_argument);
  bad_cyclic.cyclic = {.amplitude_mm = -1.0, .period_mm = 300.0, .phase_rad = 0.0};
  EXPECT_THROW(bad_cyclic.Check(), std::invalid_argument);
  DepthErrorModel bad;
  bad.c2 = -1.0;
  EXPECT_THROW(bad.Check(), std::invalid_argument);
  EXPECT_THROW(ParseAngleTerm("cos"), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
