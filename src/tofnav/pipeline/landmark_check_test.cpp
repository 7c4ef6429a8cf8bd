// SPDX-License-Identifier: BSD-3-Clause
// LandmarkCheck on synthetic pointer paths with known errors (issue 37 item 6).
#include "tofnav/pipeline/landmark_check.hpp"

#include <gtest/gtest.h>

#include <random>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr double kRateHz = 45.0;
constexpr double kJitterMm = 0.2;  // tip noise per frame (the pointer's tracking)
// The mean of >= 45 frames of 0.2 mm noise per axis: 4 sigma of the mean's norm.
constexpr double kMeanTolMm = 4.0 * kJitterMm * 1.8 / 6.7;

const Eigen::Vector3d kTip(0.0, 0.0, 150.0);  // tip in the pointer's frame

Rigid3d ToolFromImage() {
  return {Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized())),
          Eigen::Vector3d(40.0, -60.0, 120.0)};
}

std::vector<Landmark> Landmarks() {
  return {{"nasion", {0.0, -95.0, 10.0}},
          {"right_canthus", {-45.0, -80.0, 0.0}},
          {"left_canthus", {45.0, -80.0, 0.0}}};
}

// Builds the frames of a pointer whose tip goes to each point in turn, rests there for
// `rest_s`, and moves 30 mm away in between.
class Pointer {
 public:
  explicit Pointer(std::uint32_t seed, double spike_fraction = 0.0)
      : rng_(seed), spike_fraction_(spike_fraction) {}
  std::vector<NavigationState> frames;
  void RestAt(const Eigen::Vector3d& tip_in_image, double rest_s) {
    MoveTo(tip_in_image + Eigen::Vector3d(0.0, -30.0, 10.0), 0.5);
    MoveTo(tip_in_image, 0.4);
    for (int k = 0; k < static_cast<int>(rest_s * kRateHz); ++k) Emit(tip_in_image, true);
    MoveTo(tip_in_image + Eigen::Vector3d(0.0, -30.0, 10.0), 0.4);
  }
  void Lost(double s) {
    for (int k = 0; k < static_cast<int>(s * kRateHz); ++k) Emit({}, false);
  }

 private:
  void MoveTo(const Eigen::Vector3d& to, double s) {
    const Eigen::Vector3d from = at_;
    const int n = static_cast<int>(s * kRateHz);
    for (int k = 1; k <= n; ++k) Emit(from + (to - from) * k / n, true);
  }
  void Emit(const Eigen::Vector3d& tip_in_image, bool seen) {
    NavigationState s;
    s.timestamp_s = t_s_;
    t_s_ += 1.0 / kRateHz;
    if (seen) {
      at_ = tip_in_image;
      std::normal_distribution<double> noise(0.0, kJitterMm);
      Eigen::Vector3d error(noise(rng_), noise(rng_), noise(rng_));
      if (std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < spike_fraction_) {
        error += kSpikeMm * Eigen::Vector3d(noise(rng_), noise(rng_), noise(rng_)).normalized();
      }
      const Eigen::Vector3d tip_in_tool = ToolFromImage() * tip_in_image + error;
      // Any pointer orientation; the tip lands at tip_in_tool.
      const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3 * t_s_, Eigen::Vector3d::UnitY()));
      s.tool_from_instrument = Rigid3d(q, tip_in_tool - q * kTip);
    }
    frames.push_back(s);
  }
  static constexpr double kSpikeMm = 3.5;  // the pointer's angular noise at its tip
  std::mt19937 rng_;
  double spike_fraction_;
  double t_s_ = 100.0;
  Eigen::Vector3d at_ = Eigen::Vector3d(0.0, -200.0, 50.0);
};

TEST(LandmarkCheck, EachRestIsATouchOfTheAskedLandmarkWithItsError) {
  const std::vector<Eigen::Vector3d> offsets{{0.3, 0.0, 0.0}, {0.0, -1.2, 0.5}, {2.4, 0.0, 1.0}};
  Pointer p(7);
  for (std::size_t i = 0; i < 3; ++i) p.RestAt(Landmarks()[i].in_image + offsets[i], 1.5);
  LandmarkCheck check(Landmarks(), ToolFromImage(), kTip);
  EXPECT_EQ(check.StatusLine(), "verify: touch nasion (1 of 3)");
  int touches = 0;
  for (const NavigationState& s : p.frames) touches += check.Add(s) ? 1 : 0;
  ASSERT_EQ(touches, 3);  // one per rest, though each rest lasts 1.5 s
  ASSERT_TRUE(check.done());
  for (std::size_t i = 0; i < 3; ++i) {
    const LandmarkTouch& t = check.touches()[i];
    EXPECT_EQ(t.landmark, static_cast<int>(i));
    EXPECT_LT((t.error_in_image - offsets[i]).norm(), kMeanTolMm) << i;
    EXPECT_NEAR(t.error_mm, offsets[i].norm(), kMeanTolMm) << i;
    EXPECT_GE(t.end_s - t.start_s, 1.0);
    EXPECT_FALSE(t.nearer_landmark.has_value());
  }
  EXPECT_TRUE(check.touches()[0].pass);
  EXPECT_TRUE(check.touches()[1].pass);
  EXPECT_FALSE(check.touches()[2].pass);  // 2.6 mm > 2 mm
  EXPECT_FALSE(check.passed());
  char expected[160];
  std::snprintf(expected, sizeof expected,
                "verify FAILED: largest error %.2f mm (limit 2.00 mm); left_canthus %.2f mm",
                check.touches()[2].error_mm, check.touches()[2].error_mm);
  EXPECT_EQ(check.StatusLine(), expected);
}

// The tracked tip scatters with spikes of several millimetres (angular noise times the
// pointer's length): a rest is still found, and its spikes do not bias the touch.
TEST(LandmarkCheck, SpikesInTheTipDoNotBreakOrBiasARest) {
  const Eigen::Vector3d offset(0.0, 0.8, -0.6);
  Pointer p(11, 0.15);
  for (std::size_t i = 0; i < 3; ++i) p.RestAt(Landmarks()[i].in_image + offset, 1.5);
  LandmarkCheck check(Landmarks(), ToolFromImage(), kTip);
  for (const NavigationState& s : p.frames) check.Add(s);
  ASSERT_TRUE(check.done());
  for (const LandmarkTouch& t : check.touches()) {
    EXPECT_LT((t.error_in_image - offset).norm(), kMeanTolMm) << t.landmark;
  }
  EXPECT_TRUE(check.passed());
}

TEST(LandmarkCheck, ShortRestsAndLostFramesAreNotTouches) {
  Pointer p(8);
  p.RestAt(Landmarks()[0].in_image, 0.7);  // too short
  p.Lost(0.5);
  p.RestAt(Landmarks()[0].in_image, 0.6);  // short again: the gap restarts the rest
  LandmarkCheck check(Landmarks(), ToolFromImage(), kTip);
  for (const NavigationState& s : p.frames) EXPECT_FALSE(check.Add(s).has_value());
  EXPECT_EQ(check.StatusLine(), "verify: touch nasion (1 of 3)");
}

// A rest taken while the reference is SETTLING (its orientation one frame's fit, docs/navigation.md
// 1.2) is not a touch: the check judges the registration, not a reference still being averaged.
TEST(LandmarkCheck, NoTouchWhileTheReferenceIsSettling) {
  Pointer p(9);
  p.RestAt(Landmarks()[0].in_image, 1.5);
  LandmarkCheck check(Landmarks(), ToolFromImage(), kTip);
  for (NavigationState s : p.frames) {
    s.reference_settling = true;
    EXPECT_FALSE(check.Add(s).has_value());
  }
  int touches = 0;
  for (const NavigationState& s : p.frames) touches += check.Add(s) ? 1 : 0;  // the same, settled
  EXPECT_EQ(touches, 1);
}

TEST(LandmarkCheck, AWrongLandmarkIsNamedAndFails) {
  Pointer p(9);
  p.RestAt(Landmarks()[1].in_image, 1.2);  // asked for the nasion, touched the right canthus
  LandmarkCheck check(Landmarks(), ToolFromImage(), kTip);
  std::optional<LandmarkTouch> touch;
  for (const NavigationState& s : p.frames) {
    if (auto t = check.Add(s)) touch = t;
  }
  ASSERT_TRUE(touch.has_value());
  EXPECT_EQ(touch->nearer_landmark, 1);
  EXPECT_FALSE(touch->pass);
  char expected[160];
  std::snprintf(expected, sizeof expected,
                "verify: touch right_canthus (2 of 3); nasion %.2f mm TOO FAR", touch->error_mm);
  EXPECT_EQ(check.StatusLine(), expected);
}

TEST(LandmarkCheck, BadOptionsAreRefused) {
  LandmarkCheckOptions o;
  o.still_time_s = 0.0;
  EXPECT_THROW(LandmarkCheck(Landmarks(), ToolFromImage(), kTip, o), PreconditionError);
  EXPECT_THROW(LandmarkCheck({}, ToolFromImage(), kTip), PreconditionError);
}

}  // namespace
}  // namespace tofnav
