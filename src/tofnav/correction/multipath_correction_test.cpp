// SPDX-License-Identifier: BSD-3-Clause
// Multipath removal against the simulator's one-bounce rendering: a concave corner's indirect
// light is removed, a convex corner and a flat board are left alone.
#include "tofnav/correction/multipath_correction.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "tofnav/correction/range_normals.hpp"
#include "tofnav/sim/render.hpp"
#include "tofnav/sim/sim_test_scenes.hpp"
#include "tofnav/sim/tof_model.hpp"

namespace tofnav {
namespace {

using sim::testing::CentrePixel;
using sim::testing::TestCamera;
using sim::testing::WindowAround;

// The simulator renders its indirect light on a finer grid (8 px) than the correction predicts it
// (16 px), so the test does not check the correction against its own discretisation.
sim::RenderResult Render(const sim::Scene& scene, double gain,
                         sim::BiasMode mode = sim::BiasMode::kNone) {
  sim::RenderOptions options = sim::IdealRenderOptions();
  options.bias_mode = mode;
  options.window = WindowAround(CentrePixel().x(), CentrePixel().y(), 200);
  options.multipath = {gain, 8, 8};
  std::mt19937_64 rng(1);
  return sim::RenderAhatFrame(scene, TestCamera(), Rigid3d::Identity(), options, rng);
}

// Two 200 x 400 mm walls of albedo 0.8 meeting in a vertical crease at z = 500 mm, each at 45 deg
// to the optical axis: open towards the camera (concave) or pointing at it (convex).
sim::Scene CornerScene(bool concave, const sim::Material& material = sim::DiffuseMaterial(0.8)) {
  sim::Scene scene;
  const int m = scene.AddMaterial(material);
  const Eigen::Quaterniond flip(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()));
  const double half = 100.0 * std::numbers::sqrt2 / 2.0, depth = concave ? -half : half;
  for (const double side : {-1.0, 1.0}) {
    const double tilt_rad = (concave ? side : -side) * std::numbers::pi / 4.0;
    const Eigen::Quaterniond tilt(Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d::UnitY()));
    scene.AddObject(side < 0 ? "left" : "right", sim::PlaneMesh(200.0, 400.0), m,
                    Rigid3d(tilt * flip, {side * half, 0.0, 500.0 + depth}));
  }
  return scene;
}

MultipathCorrectionOptions OptionsFor(const sim::RenderOptions& render) {
  MultipathCorrectionOptions options;
  options.ab_scale = render.radiometry.ab_scale;  // the device constant, known to the user
  options.falloff_power = render.radiometry.falloff_power;
  return options;
}

struct Residual {
  double before_mm = 0.0;  // mean of measured - multipath-free range
  double after_mm = 0.0;   // mean of corrected - multipath-free range
  double after_abs_mm = 0.0;
  int pixels = 0;
};

// Over the pixels at least 4 px from the crease (the crease's own pixels mix both walls).
Residual Compare(const sim::RenderResult& on, const sim::RenderResult& off,
                 const Image<float>& corrected) {
  Residual r;
  const Eigen::Vector2i c = CentrePixel();
  for (int v = c.y() - 60; v <= c.y() + 60; ++v) {
    for (int u = c.x() - 90; u <= c.x() + 90; ++u) {
      if (std::abs(u - c.x()) < 4 || off.truth_range_mm(u, v) <= 0.0f || corrected(u, v) <= 0.0f ||
          off.frame.range_mm(u, v) >= kAhatInvalidRange) {
        continue;
      }
      const double reference = off.frame.range_mm(u, v);
      r.before_mm += on.frame.range_mm(u, v) - reference;
      r.after_mm += corrected(u, v) - reference;
      r.after_abs_mm += std::abs(corrected(u, v) - reference);
      ++r.pixels;
    }
  }
  if (r.pixels > 0) {
    r.before_mm /= r.pixels;
    r.after_mm /= r.pixels;
    r.after_abs_mm /= r.pixels;
  }
  return r;
}

TEST(RemoveMultipath, TakesAConcaveCornersIndirectLightOut) {
  constexpr double kMinShiftMm = 3.0;  // the corner's multipath (docs/simulator.md: 7.5 mm)
  // Left after removal: both depths are rounded to 1 mm (0.5 mm mean absolute each), and the
  // correction predicts on a coarser grid than the rendering; a tenth of the shift on average.
  constexpr double kMeanFraction = 0.1;
  constexpr double kMeanAbsMm = 0.8;
  const sim::Scene scene = CornerScene(true);
  const sim::RenderResult on = Render(scene, 1.0), off = Render(scene, 0.0);
  MultipathCorrectionStats stats;
  const Image<float> corrected =
      RemoveMultipath(RangeAsFloat(on.frame.range_mm), on.frame.ab, TestCamera(),
                      OptionsFor(sim::IdealRenderOptions()), {}, {}, &stats);
  const Residual r = Compare(on, off, corrected);
  RecordProperty("shift_before_mm", std::to_string(r.before_mm));
  RecordProperty("residual_mean_mm", std::to_string(r.after_mm));
  RecordProperty("residual_mean_abs_mm", std::to_string(r.after_abs_mm));
  EXPECT_GT(r.pixels, 10000);
  EXPECT_GT(r.before_mm, kMinShiftMm);
  EXPECT_LT(std::abs(r.after_mm), kMeanFraction * r.before_mm);
  EXPECT_LT(r.after_abs_mm, kMeanAbsMm);
  EXPECT_GT(stats.pixels_corrected, r.pixels);
  EXPECT_GT(stats.mean_shift_mm, kMinShiftMm);
}

TEST(RemoveMultipath, AddsTheSurfacesScatteringDelayToTheIndirectPath) {
  // A skin-like corner (subsurface delay 52 ps, all light delayed: 7.4 mm at 142 MHz) in the
  // physical mode: its direct light is delayed once, its indirect light twice (at both walls), so
  // the indirect path is 2 x 7.4 mm longer than the measured ranges say. Given the delay, the
  // removal must meet the delay-free corner's bound; without it, it leaves much more.
  constexpr double kMeanFraction = 0.1;  // as TakesAConcaveCornersIndirectLightOut
  sim::Material skin = sim::DiffuseMaterial(0.8);
  skin.subsurface_fraction = 1.0;
  skin.subsurface_delay_ps = 52.0;
  const double delay_mm = sim::SubsurfaceBiasMm(skin, 0.0, sim::IdealRenderOptions().sensor);
  ASSERT_GT(delay_mm, 7.0);
  const sim::Scene scene = CornerScene(true, skin);
  const sim::RenderResult on = Render(scene, 1.0, sim::BiasMode::kPhysical),
                          off = Render(scene, 0.0, sim::BiasMode::kPhysical);
  const Image<float> measured = RangeAsFloat(on.frame.range_mm);
  const Image<std::uint8_t> everywhere(measured.width(), measured.height(), 1);
  const Image<float> delay = SkinScatterDelay(everywhere, delay_mm);
  const MultipathCorrectionOptions options = OptionsFor(sim::IdealRenderOptions());
  const Residual with = Compare(on, off,
                                RemoveMultipath(measured, on.frame.ab, TestCamera(), options, {},
                                                {.scatter_delay_mm = &delay}));
  const Residual without =
      Compare(on, off, RemoveMultipath(measured, on.frame.ab, TestCamera(), options));
  RecordProperty("shift_before_mm", std::to_string(with.before_mm));
  RecordProperty("residual_with_delay_mm", std::to_string(with.after_mm));
  RecordProperty("residual_without_delay_mm", std::to_string(without.after_mm));
  EXPECT_GT(with.pixels, 10000);
  EXPECT_LT(std::abs(with.after_mm), kMeanFraction * with.before_mm);
  // Without the delay the indirect phase is read short and too little is removed.
  EXPECT_GT(without.after_mm, with.after_mm + 0.04 * with.before_mm);
  EXPECT_EQ(SkinScatterDelay(everywhere, 0.0).size(), 0u);  // no delay: no hint
}

TEST(RemoveMultipath, DampedPassesSettleWhereUndampedOnesAlternate) {
  // The damped fixed point (docs/correction.md 7.1) must keep the corner's residual within the
  // undamped test's bounds at every pass count, and its last two passes must agree more closely
  // than the undamped ones, which over- and under-correct in turn.
  constexpr double kMeanFraction = 0.1;  // as TakesAConcaveCornersIndirectLightOut
  constexpr double kMeanAbsMm = 0.8;
  const sim::Scene scene = CornerScene(true);
  const sim::RenderResult on = Render(scene, 1.0), off = Render(scene, 0.0);
  const Image<float> measured = RangeAsFloat(on.frame.range_mm);
  const auto correct = [&](int passes, bool damped) {
    MultipathCorrectionOptions options = OptionsFor(sim::IdealRenderOptions());
    options.passes = passes;
    options.damped = damped;
    return RemoveMultipath(measured, on.frame.ab, TestCamera(), options);
  };
  const auto change_mm = [](const Image<float>& a, const Image<float>& b) {
    double sum = 0.0;
    int n = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (a.pixels()[i] > 0.0f && b.pixels()[i] > 0.0f) {
        sum += std::abs(a.pixels()[i] - b.pixels()[i]);
        ++n;
      }
    }
    return n > 0 ? sum / n : 0.0;
  };
  // Two passes: the damping starts at the third, so the ranges are the same.
  EXPECT_EQ(change_mm(correct(2, true), correct(2, false)), 0.0);
  for (const int passes : {3, 4, 5}) {
    const Residual r = Compare(on, off, correct(passes, true));
    RecordProperty("damped_" + std::to_string(passes) + "_mean_mm", std::to_string(r.after_mm));
    EXPECT_LT(std::abs(r.after_mm), kMeanFraction * r.before_mm) << passes;
    EXPECT_LT(r.after_abs_mm, kMeanAbsMm) << passes;
  }
  const double damped_step_mm = change_mm(correct(5, true), correct(6, true));
  const double undamped_step_mm = change_mm(correct(5, false), correct(6, false));
  RecordProperty("damped_step_mm", std::to_string(damped_step_mm));
  RecordProperty("undamped_step_mm", std::to_string(undamped_step_mm));
  EXPECT_LT(damped_step_mm, undamped_step_mm);
}

TEST(RemoveMultipath, LeavesAConvexCornerAndAFlatBoardAlone) {
  // Surfaces that do not face each other exchange no light: nothing to remove.
  constexpr double kToleranceMm = 0.01;
  for (const bool board : {false, true}) {
    const sim::Scene scene =
        board ? sim::testing::BoardScene(sim::DiffuseMaterial(0.8), 450.0) : CornerScene(false);
    const sim::RenderResult on = Render(scene, 1.0);
    const Image<float> measured = RangeAsFloat(on.frame.range_mm);
    MultipathCorrectionStats stats;
    const Image<float> corrected = RemoveMultipath(
        measured, on.frame.ab, TestCamera(), OptionsFor(sim::IdealRenderOptions()), {}, {}, &stats);
    EXPECT_GT(stats.pixels_corrected, 10000) << board;
    EXPECT_LT(std::abs(stats.mean_shift_mm), kToleranceMm) << board;
    EXPECT_EQ(stats.pixels_dropped, 0) << board;
  }
}

TEST(RemoveMultipath, ReportsTheIndirectRatioThatBoundsEachPixelsShift) {
  // The ratio |q| is what reconstruct weighs pixels by: it must be large where the removal acts
  // and bound what it removes, |shift| = |arg(1 + q)| / 2k <= asin |q| / 2k, and be small where
  // surfaces exchange no light.
  constexpr double kMinMeanRatio = 0.02;       // the corner's 7.5 mm shift needs a few per cent
  constexpr double kRoundingMm = 1e-3;         // float ranges near 500 mm
  constexpr double kFlatRatioFraction = 0.05;  // a flat board: a twentieth of the corner's
  const MultipathCorrectionOptions options = OptionsFor(sim::IdealRenderOptions());
  const double half_k = 2.0 * std::numbers::pi / (2.0 * options.alias_mm);  // 2k / 2
  const auto mean_ratio = [&](const sim::Scene& scene) {
    const sim::RenderResult on = Render(scene, 1.0);
    const Image<float> measured = RangeAsFloat(on.frame.range_mm);
    Image<float> ratio;
    const Image<float> corrected = RemoveMultipath(measured, on.frame.ab, TestCamera(), options, {},
                                                   {.indirect_ratio = &ratio});
    EXPECT_EQ(ratio.width(), measured.width());
    double sum = 0.0;
    int count = 0;
    for (std::size_t i = 0; i < ratio.size(); ++i) {
      if (corrected.pixels()[i] <= 0.0f) continue;
      const double q = ratio.pixels()[i];
      const double shift = measured.pixels()[i] - corrected.pixels()[i];
      EXPECT_LE(std::abs(shift), std::asin(std::min(q, 1.0)) / (2.0 * half_k) + kRoundingMm) << i;
      sum += q;
      ++count;
    }
    EXPECT_GT(count, 10000);
    return sum / std::max(count, 1);
  };
  const double corner = mean_ratio(CornerScene(true));
  const double board = mean_ratio(sim::testing::BoardScene(sim::DiffuseMaterial(0.8), 450.0));
  RecordProperty("corner_mean_ratio", std::to_string(corner));
  RecordProperty("board_mean_ratio", std::to_string(board));
  EXPECT_GT(corner, kMinMeanRatio);
  EXPECT_LT(board, kFlatRatioFraction * corner);
}

TEST(RemoveMultipath, HintsGiveTheSameRangesWhereWantedAndLeaveTheRestMeasured) {
  const sim::RenderResult on = Render(CornerScene(true), 1.0);
  const Image<float> measured = RangeAsFloat(on.frame.range_mm);
  const MultipathCorrectionOptions options = OptionsFor(sim::IdealRenderOptions());
  const Image<float> full = RemoveMultipath(measured, on.frame.ab, TestCamera(), options);
  const Image<Eigen::Vector3f> normal = ComputeRangeNormals(measured, TestCamera()).normal;
  Image<std::uint8_t> wanted(measured.width(), measured.height(), 0);
  for (int v = 0; v < wanted.height(); ++v) {
    for (int u = 0; u < CentrePixel().x(); ++u) wanted(u, v) = 1;  // the left wall
  }
  const Image<float> hinted =
      RemoveMultipath(measured, on.frame.ab, TestCamera(), options, {}, {&normal, &wanted});
  int compared = 0;
  for (int v = 0; v < measured.height(); ++v) {
    for (int u = 0; u < measured.width(); ++u) {
      if (wanted(u, v) != 0) {
        ASSERT_EQ(hinted(u, v), full(u, v)) << u << ", " << v;
        compared += measured(u, v) > 0.0f;
      } else {
        ASSERT_EQ(hinted(u, v), measured(u, v)) << u << ", " << v;
      }
    }
  }
  EXPECT_GT(compared, 10000);
}

// A lossy stream's AB arrives as hl2ss's square code c^2 (docs/ahat.md 3.6.1), the floor of the
// interval [c^2, (c + 1)^2) that the code stands for. Read at the interval's centre, the emitters'
// albedos and with them the removed shift are those of the true AB.
TEST(RemoveMultipath, ReadsALossyStreamsSquareCodeAtItsIntervalsCentre) {
  // The floor of each code reads the walls' AB (a few hundred counts) about 5 % low, and the
  // removed shift with it (4.6 % here).
  constexpr double kFloorLowBy = 0.03;
  // The centre is exact for an AB spread evenly over a code's interval; over smoothly varying
  // walls the codes' offsets average out to well under a tenth of that.
  constexpr double kCentreWithin = 0.01;
  const sim::RenderResult on = Render(CornerScene(true), 1.0);
  const Image<float> measured = RangeAsFloat(on.frame.range_mm);
  Image<std::uint16_t> coded = on.frame.ab;
  for (std::uint16_t& x : coded.pixels()) {
    const auto c = static_cast<std::uint16_t>(std::floor(std::sqrt(static_cast<double>(x))));
    x = static_cast<std::uint16_t>(c * c);
  }
  const MultipathCorrectionOptions options = OptionsFor(sim::IdealRenderOptions());
  const auto mean_shift = [&](const Image<std::uint16_t>& ab, bool square_code) {
    MultipathCorrectionStats stats;
    RemoveMultipath(measured, ab, TestCamera(), options, {}, {.ab_square_code = square_code},
                    &stats);
    return stats.mean_shift_mm;
  };
  const double raw = mean_shift(on.frame.ab, false);
  const double floor = mean_shift(coded, false), centre = mean_shift(coded, true);
  RecordProperty("shift_raw_mm", std::to_string(raw));
  RecordProperty("shift_square_code_floor_mm", std::to_string(floor));
  RecordProperty("shift_square_code_centre_mm", std::to_string(centre));
  EXPECT_LT(floor, (1.0 - kFloorLowBy) * raw);
  EXPECT_NEAR(centre, raw, kCentreWithin * raw);
}

TEST(RemoveMultipath, OffReturnsTheRangeUnchangedAndBadInputIsRefused) {
  const sim::RenderResult on = Render(CornerScene(true), 1.0);
  const Image<float> measured = RangeAsFloat(on.frame.range_mm);
  MultipathCorrectionOptions off;
  off.enabled = false;
  const Image<float> same = RemoveMultipath(measured, on.frame.ab, TestCamera(), off);
  for (std::size_t i = 0; i < measured.size(); ++i) {
    ASSERT_EQ(same.pixels()[i], measured.pixels()[i]);
  }
  MultipathCorrectionOptions bad;
  bad.ab_scale = 0.0;
  EXPECT_THROW(RemoveMultipath(measured, on.frame.ab, TestCamera(), bad), std::invalid_argument);
  bad = {};
  bad.passes = 0;
  EXPECT_THROW(bad.Check(), std::invalid_argument);
  EXPECT_THROW(RemoveMultipath(Image<float>(8, 8), on.frame.ab, TestCamera(), {}),
               std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
