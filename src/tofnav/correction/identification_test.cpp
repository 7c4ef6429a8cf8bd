// SPDX-License-Identifier: BSD-3-Clause
// Identification (Eq. 5-7) on analytic sphere "heads" with a known linear bias.
#include "tofnav/correction/identification.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "correction_test_scenes.hpp"
#include "tofnav/core/statistics.hpp"

namespace tofnav {
namespace {

using testing::kHeadRadiusMm;
using testing::SphereFrames;
using testing::SphereSkin;
using testing::TrueModel;

TEST(SmoothnessDistances, ZeroForTheTrueModelAndOffsetForNone) {
  constexpr double kFitTolMm = 0.02;  // a cubic patch on a 90 mm sphere over 22 mm
  const std::vector<IdentificationFrame> frames = SphereFrames(TrueModel());
  for (const MarkerPatch& patch : frames[1].markers) {
    EXPECT_LT(Rms(SmoothnessDistances(patch, TrueModel())), kFitTolMm);
    // Uncorrected: the head lies C1 + C2 d + C3 theta farther, the markers (unbiased) closer.
    EXPECT_GT(Rms(SmoothnessDistances(patch, DepthErrorModel{})), 5.0);
  }
}

// The identification keeps each patch's decycled ranges while only the coefficients change: the
// distances must be bit for bit those computed afresh, whether the cyclic error is kept, changed
// or switched off between calls.
TEST(SmoothnessDistances, DecycledRangesChangeNoFigure) {
  DepthErrorModel model = TrueModel();
  model.cyclic = {1.2, 1055.0 / 3.0, 0.4};
  const std::vector<IdentificationFrame> frames = SphereFrames(model);
  const MarkerPatch& patch = frames[1].markers.front();
  DecycledRanges kept;
  const auto check = [&](const DepthErrorModel& m) {
    EXPECT_EQ(SmoothnessDistances(patch, m, &kept), SmoothnessDistances(patch, m));
  };
  check(model);
  model.c1_mm += 0.3;  // the cyclic error as before: the kept ranges serve
  check(model);
  model.c3_mm -= 0.2;
  check(model);
  model.cyclic.phase_rad += 1e-9;  // any change of it recomputes them
  check(model);
  EXPECT_EQ(kept.key.phase_rad, model.cyclic.phase_rad);
  model.cyclic = {};  // off: nothing kept is used
  check(model);
}

// The fitted model at the references the truth was written at (theta 0, AB_ref 130): the
// identification centres its own on the samples (exactly the same bias function).
DepthErrorModel AtOrigin(const DepthErrorModel& fitted) {
  return fitted.WithReferences(0.0, DepthErrorModel{}.ab_reference);
}

// The simulator's nylon in the intensity form: C1 9 mm, C3 2.7 mm/rad, C4 2 mm per ln unit.
DepthErrorModel NylonIntensityForm() {
  DepthErrorModel truth = IntensityFormModel();
  truth.c1_mm = 9.0;
  truth.c3_mm = 2.7;
  truth.c4_mm = 2.0;
  return truth;
}

TEST(IdentifyDepthModel, SmoothnessOnlyRecoversKnownCoefficients) {
  constexpr double kRelTol = 0.02;  // noise-free: limited by the cubic patch fit
  const std::vector<IdentificationFrame> frames = SphereFrames(TrueModel());
  const DepthErrorModel fitted = IdentifyDepthModel(frames, nullptr, DepthErrorModel{});
  EXPECT_NEAR(AtOrigin(fitted).c1_mm, 2.8, 2.8 * kRelTol);
  EXPECT_NEAR(fitted.c2, 0.010, 0.010 * kRelTol);
  EXPECT_NEAR(fitted.c3_mm, 4.0, 4.0 * kRelTol);
  EXPECT_EQ(fitted.report.costs, "smoothness");
  ASSERT_EQ(fitted.report.frames.size(), 4u);
  EXPECT_LT(fitted.report.frames[0].err_s_mm, 0.02);
  EXPECT_LT(fitted.report.final_cost, 1e-3 * fitted.report.initial_cost);
}

TEST(IdentifyDepthModel, TheIntensityFormRecoversItsCoefficientsAtTheSamplesCentre) {
  constexpr double kRelTol = 0.03;  // noise-free: the cubic patch fit (as above), three terms
  const DepthErrorModel truth = NylonIntensityForm();
  const std::vector<IdentificationFrame> frames = SphereFrames(truth, /*lambertian_ab=*/true);
  const DepthErrorModel fitted = IdentifyDepthModel(frames, nullptr, IntensityFormModel());
  EXPECT_EQ(fitted.Name(), "intensity-theta");
  EXPECT_EQ(fitted.c2, 0.0);
  EXPECT_NEAR(AtOrigin(fitted).c1_mm, 9.0, 9.0 * kRelTol);
  EXPECT_NEAR(fitted.c3_mm, 2.7, 2.7 * kRelTol);
  EXPECT_NEAR(fitted.c4_mm, 2.0, 2.0 * kRelTol);
  EXPECT_EQ(fitted.report.standard_errors.size(), 3u);  // C1, C3, C4: C2 is not a parameter
  EXPECT_LT(fitted.report.final_cost, 1e-3 * fitted.report.initial_cost);
  // C1 is the bias at the head samples' median theta and AB (docs/correction.md 2.7); the
  // uncentred fit gives the same bias function with C1 at theta 0, AB 130.
  constexpr double kBiasTolMm = 0.05;  // two noise-free fits of the same cost
  std::vector<double> theta, ab;       // the head samples, else the markers' neighbours
  auto add = [&](const SurfaceSample& x) {
    if (std::isfinite(x.incidence_rad)) theta.push_back(x.incidence_rad);
    if (std::isfinite(x.ab) && x.ab > 0.0f) ab.push_back(x.ab);
  };
  for (const IdentificationFrame& f : frames) std::ranges::for_each(f.head, add);
  const bool heads = !theta.empty();
  for (const IdentificationFrame& f : frames) {
    for (const MarkerPatch& p : f.markers) {
      if (!heads) std::ranges::for_each(p.neighbours, add);
    }
  }
  ASSERT_FALSE(theta.empty());
  EXPECT_DOUBLE_EQ(fitted.theta_reference_rad, Median(theta));
  EXPECT_DOUBLE_EQ(fitted.ab_reference, Median(ab));
  EXPECT_NEAR(fitted.c1_mm, truth.BiasMm(0.0, Median(theta), Median(ab)), kBiasTolMm);
  IdentificationOptions uncentred;
  uncentred.centre_references = false;
  const DepthErrorModel plain =
      IdentifyDepthModel(frames, nullptr, IntensityFormModel(), uncentred);
  EXPECT_EQ(plain.theta_reference_rad, 0.0);
  EXPECT_EQ(plain.ab_reference, 130.0);
  for (double t : {0.1, 0.6, 1.1}) {
    for (double a : {50.0, 300.0}) {
      EXPECT_NEAR(fitted.BiasMm(400.0, t, a), plain.BiasMm(400.0, t, a), kBiasTolMm);
    }
  }
}

TEST(IdentifyDepthModel, FitsTheSensorsCyclicErrorWithTheCoefficients) {
  constexpr double kAmplitudeTolMm = 0.01;  // noise-free: the cubic patch fit, as above
  constexpr double kPhaseTolRad = 0.01;
  constexpr double kC1TolMm = 0.05;
  constexpr double kPeriodMm = 1055.0 / 3.0;  // the simulated sensor's L / 3
  DepthErrorModel truth = NylonIntensityForm();
  truth.cyclic = {1.0, kPeriodMm, 0.5};
  // Nine views from 350 to 750 mm: the wiggle's 1.1 periods seen by the stickers' neighbours.
  std::vector<IdentificationFrame> frames;
  for (int i = 0; i < 9; ++i) {
    const Eigen::Vector3d centre = Eigen::AngleAxisd(0.1 * i - 0.4, Eigen::Vector3d::UnitX()) *
                                   Eigen::Vector3d(10.0 * i - 40.0, 0.0, 350.0 + 50.0 * i);
    frames.push_back(testing::SphereFrame(i, centre, truth, 8, 4.3, /*lambertian_ab=*/true));
  }
  IdentificationOptions options;
  options.fit_cyclic_period_mm = kPeriodMm;
  const DepthErrorModel fitted = IdentifyDepthModel(frames, nullptr, IntensityFormModel(), options);
  EXPECT_NEAR(fitted.cyclic.amplitude_mm, 1.0, kAmplitudeTolMm);
  EXPECT_NEAR(fitted.cyclic.phase_rad, 0.5, kPhaseTolRad);
  EXPECT_DOUBLE_EQ(fitted.cyclic.period_mm, kPeriodMm);
  EXPECT_NEAR(AtOrigin(fitted).c1_mm, 9.0, kC1TolMm);
  EXPECT_EQ(fitted.report.standard_errors.size(), 5u);  // C1, C3, C4, then A cos phi, A sin phi
  // Held at none, the coefficients absorb what they can of the wiggle and leave the rest.
  const DepthErrorModel held = IdentifyDepthModel(frames, nullptr, IntensityFormModel());
  EXPECT_FALSE(held.cyclic.enabled());
  EXPECT_GT(held.report.final_cost, 100.0 * fitted.report.final_cost);
}

TEST(IdentifyDepthModel, LeavesOutMarkersThatAreNotOnTheSkin) {
  constexpr double kRelTol = 0.02;  // as SmoothnessOnlyRecoversKnownCoefficients
  // A tool's marker on its plate: its surroundings carry no skin bias (frames made with the zero
  // model), so the skin model over-corrects them by the whole bias. One such marker per frame.
  std::vector<IdentificationFrame> frames = SphereFrames(TrueModel());
  const std::vector<IdentificationFrame> unbiased = SphereFrames(DepthErrorModel{});
  for (std::size_t f = 0; f < frames.size(); ++f)
    frames[f].markers.push_back(unbiased[f].markers[0]);
  const DepthErrorModel fitted = IdentifyDepthModel(frames, nullptr, DepthErrorModel{});
  EXPECT_EQ(fitted.report.marker_observations_rejected, static_cast<int>(frames.size()));
  EXPECT_NEAR(AtOrigin(fitted).c1_mm, 2.8, 2.8 * kRelTol);
  EXPECT_NEAR(fitted.c2, 0.010, 0.010 * kRelTol);
  EXPECT_NEAR(fitted.c3_mm, 4.0, 4.0 * kRelTol);
  // Kept, they pull the fit off (the Huber loss bounds each one's pull, not its direction).
  IdentificationOptions keep;
  keep.reject_outlier_markers = false;
  const DepthErrorModel pulled = IdentifyDepthModel(frames, nullptr, DepthErrorModel{}, keep);
  EXPECT_EQ(pulled.report.marker_observations_rejected, 0);
  EXPECT_GT(std::abs(AtOrigin(pulled).c1_mm - 2.8) / 2.8 + std::abs(pulled.c2 - 0.010) / 0.010 +
                std::abs(pulled.c3_mm - 4.0) / 4.0,
            5.0 * kRelTol);
}

TEST(CorrectnessDistances, ZeroForTheTrueModelAndTheBiasForNone) {
  constexpr double kSkinTolMm = 0.15;  // point-to-plane to a 3 deg (4.7 mm) skin sampling
  const std::vector<IdentificationFrame> frames = SphereFrames(TrueModel());
  const SurfaceIndex skin(SphereSkin());
  CorrectnessOptions options;
  options.icp.max_iterations_per_level = 8;  // a sphere never pins the rotation
  options.icp.max_distance_schedule_mm = {15.0, 6.0, 3.0};
  const Rigid3d guess = testing::SphereImageFromAhat(frames[1], Eigen::Vector3d(1.0, -1.0, 2.0));
  const CorrectnessFrame good = CorrectnessDistances(frames[1], TrueModel(), skin, guess, options);
  EXPECT_TRUE(good.converged);
  ASSERT_EQ(good.distances.size(), frames[1].marker_points.size());
  EXPECT_LT(Rms(good.distances), kSkinTolMm);
  // Uncorrected, the head cap (C1 + C2 d + C3 theta ~ 9 mm too far) registers too far out and
  // the unbiased markers end up off the skin by millimetres (how many depends on where they sit).
  const CorrectnessFrame bad =
      CorrectnessDistances(frames[1], DepthErrorModel{}, skin, guess, options);
  EXPECT_GT(Rms(bad.distances), 1.0);
}

// The weight is Err_S's beside the joint Err_C only (docs/correction.md 2.11): without a skin, Eq.
// (7) is the paper's sum whatever it is; a negative weight is refused.
TEST(IdentifyDepthModel, TheJointSmoothnessWeightLeavesASmoothnessOnlyCostAlone) {
  const std::vector<IdentificationFrame> frames = SphereFrames(TrueModel());
  DepthErrorModel off = TrueModel();
  off.c1_mm += 0.5;
  IdentificationOptions paper;
  paper.joint_smoothness_weight = 1.0;
  const IdentificationOptions tofnav;
  const double cost = EvaluateIdentificationCost(frames, nullptr, off, paper).total;
  EXPECT_GT(cost, 0.0);
  EXPECT_DOUBLE_EQ(EvaluateIdentificationCost(frames, nullptr, off, tofnav).total, cost);
  IdentificationOptions negative;
  negative.joint_smoothness_weight = -0.1;
  EXPECT_THROW(EvaluateIdentificationCost(frames, nullptr, off, negative), std::invalid_argument);
}

TEST(IdentifyDepthModel, RejectsFramesWithoutMarkers) {
  std::vector<IdentificationFrame> frames(2);
  EXPECT_THROW(IdentifyDepthModel(frames, nullptr, DepthErrorModel{}), std::invalid_argument);
}

TEST(MinimiseLeastSquares, FitsAnExponential) {
  constexpr double kTol = 1e-6;  // noise-free data
  auto residuals = [](const Eigen::VectorXd& x) {
    Eigen::VectorXd r(20);
    for (int i = 0; i < 20; ++i) {
      const double t = 0.1 * i;
      r(i) = x(0) * std::exp(x(1) * t) - 2.0 * std::exp(-1.5 * t);
    }
    return r;
  };
  const LevenbergMarquardtResult result =
      MinimiseLeastSquares(residuals, Eigen::Vector2d(1.0, 0.0), Eigen::Vector2d(1e-5, 1e-5));
  EXPECT_NEAR(result.parameters(0), 2.0, kTol);
  EXPECT_NEAR(result.parameters(1), -1.5, kTol);
  EXPECT_LT(result.final_cost, 1e-12);
}

}  // namespace
}  // namespace tofnav
