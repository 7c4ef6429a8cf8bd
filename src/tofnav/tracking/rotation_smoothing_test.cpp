// SPDX-License-Identifier: BSD-3-Clause
// SmoothWorldRotations on synthetic world_from_tool sequences: still, turning, with gaps.
#include "tofnav/tracking/rotation_smoothing.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kFrameS = 1.0 / 45.0;  // AHAT frame interval
// The reference plate's unfiltered tilt noise on the suite (0.46-0.62 deg RMS): per axis.
constexpr double kNoiseRadPerAxis = 0.5 * kDeg / 1.7320508075688772;

// A tool turning about a tilted axis at `rate_rad_per_s` (0: still) with per-axis tilt noise;
// every 7th frame has no pose (a hand over the plate).
struct Sequence {
  std::vector<std::optional<Rigid3d>> measured;
  std::vector<Eigen::Quaterniond> truth;
  std::vector<double> time_s;
};

Sequence Make(int count, double rate_rad_per_s, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, kNoiseRadPerAxis);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, 1.0, -0.3).normalized();
  const Eigen::Quaterniond start(
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 0.5, 0.0).normalized()));
  Sequence s;
  for (int i = 0; i < count; ++i) {
    const double t = i * kFrameS;
    const Eigen::Quaterniond truth =
        Eigen::Quaterniond(Eigen::AngleAxisd(rate_rad_per_s * t, axis)) * start;
    const Eigen::Vector3d e(noise(rng), noise(rng), noise(rng));
    s.time_s.push_back(t);
    s.truth.push_back(truth);
    if (i % 7 == 3) {
      s.measured.emplace_back(std::nullopt);
    } else {
      s.measured.emplace_back(
          Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(e.norm(), e.normalized())) * truth,
                  Eigen::Vector3d(10.0, 20.0, 400.0)));
    }
  }
  return s;
}

struct Rms {
  double raw = 0.0, smoothed = 0.0;
};

Rms Errors(const Sequence& s, const std::vector<std::optional<Eigen::Quaterniond>>& out) {
  double raw2 = 0.0, smoothed2 = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i].has_value(), s.measured[i].has_value()) << i;
    if (!out[i]) continue;
    raw2 += std::pow(s.measured[i]->rotation.angularDistance(s.truth[i]), 2);
    smoothed2 += std::pow(out[i]->angularDistance(s.truth[i]), 2);
    ++n;
  }
  return {std::sqrt(raw2 / n), std::sqrt(smoothed2 / n)};
}

// A still tool at 45 Hz: a +-0.5 s window holds ~39 poses, so the error falls by about
// sqrt(39) = 6 in the middle and less at the ends (a one-sided straight-line fit).
TEST(SmoothWorldRotations, AveragesTheTiltNoiseOfAStillTool) {
  constexpr double kMaxSmoothedToRaw = 0.3;  // sqrt(1/39) = 0.16 inside, ends noisier
  const Sequence s = Make(400, 0.0, 1);
  const Rms e = Errors(s, SmoothWorldRotations(s.measured, s.time_s));
  RecordProperty("raw_deg", std::to_string(e.raw / kDeg));
  RecordProperty("smoothed_deg", std::to_string(e.smoothed / kDeg));
  EXPECT_LT(e.smoothed, kMaxSmoothedToRaw * e.raw);
}

// A tool turning steadily at 10 deg/s (a turntable; a patient settling turns far slower): the
// straight-line fit has no lag, so the error still falls as for a still tool.
TEST(SmoothWorldRotations, FollowsASteadyTurnWithoutLag) {
  constexpr double kMaxSmoothedToRaw = 0.3;  // as still: the fit's line holds the turn exactly
  const Sequence s = Make(400, 10.0 * kDeg, 2);
  const Rms e = Errors(s, SmoothWorldRotations(s.measured, s.time_s));
  EXPECT_LT(e.smoothed, kMaxSmoothedToRaw * e.raw);
}

// A jump does not tilt its neighbours, a left-out pose (nullopt) is nobody's neighbour, a sample
// alone in its window is not smoothed, and bad input throws.
TEST(SmoothWorldRotations, LeavesOutJumpsMissingPosesAndLoneSamplesAndRejectsBadInput) {
  Sequence s = Make(60, 0.0, 3);
  const std::vector<std::optional<Eigen::Quaterniond>> clean =
      SmoothWorldRotations(s.measured, s.time_s);
  // A pose 30 deg off (a jump): its neighbours' second fit leaves it out, and it is far from its
  // own window's line, so it is not smoothed (the caller keeps it as measured, or drops it).
  s.measured[31] = Rigid3d(
      Eigen::Quaterniond(Eigen::AngleAxisd(30.0 * kDeg, Eigen::Vector3d::UnitX())) * s.truth[31],
      {});
  const std::vector<std::optional<Eigen::Quaterniond>> dragged =
      SmoothWorldRotations(s.measured, s.time_s);
  EXPECT_LT(dragged[29]->angularDistance(s.truth[29]), 0.2 * kDeg);  // ~0.09 deg RMS here
  EXPECT_FALSE(dragged[31].has_value());
  s.measured[31] = std::nullopt;
  const std::vector<std::optional<Eigen::Quaterniond>> left_out =
      SmoothWorldRotations(s.measured, s.time_s);
  EXPECT_FALSE(left_out[31].has_value());
  EXPECT_LT(left_out[29]->angularDistance(s.truth[29]), 0.2 * kDeg);  // ~0.09 deg RMS here
  // Alone within its window: left unsmoothed (nullopt), the caller keeps the measured pose.
  const std::vector<std::optional<Rigid3d>> lone = {s.measured[0], std::nullopt, s.measured[2]};
  const std::vector<double> lone_t = {0.0, 1.0, 2.0};
  for (const auto& r : SmoothWorldRotations(lone, lone_t)) EXPECT_FALSE(r.has_value());
  EXPECT_TRUE(clean[0].has_value());
  // Frames out of time order are smoothed as in order.
  std::vector<std::optional<Rigid3d>> shuffled(s.measured.rbegin(), s.measured.rend());
  std::vector<double> shuffled_t(s.time_s.rbegin(), s.time_s.rend());
  const std::vector<std::optional<Eigen::Quaterniond>> reversed =
      SmoothWorldRotations(shuffled, shuffled_t);
  EXPECT_LT(reversed[reversed.size() - 1 - 29]->angularDistance(*left_out[29]), 1e-12);
  shuffled_t[5] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(SmoothWorldRotations(shuffled, shuffled_t), PreconditionError);
  const std::vector<double> short_t = {0.0};
  EXPECT_THROW(SmoothWorldRotations(s.measured, short_t), PreconditionError);
  RotationSmoothingOptions bad;
  bad.half_window_s = -1.0;
  EXPECT_THROW(SmoothWorldRotations(s.measured, s.time_s, bad), PreconditionError);
  bad = {};
  bad.min_samples = 0;
  EXPECT_THROW(SmoothWorldRotations(s.measured, s.time_s, bad), PreconditionError);
  bad = {};
  bad.max_deviation_rad = 0.0;
  EXPECT_THROW(SmoothWorldRotations(s.measured, s.time_s, bad), PreconditionError);
}

// Poses measured in a camera turning at up to ~30 deg/s (a head-worn display) of a tool still in
// `world`: smoothed where the tool stands still and mapped back through each frame's camera
// pose, the orientation in `ahat` follows the camera without lag and loses most of its noise;
// positions and the frames without a camera pose stay as measured.
TEST(SmoothAhatRotations, SmoothsInTheWorldAndMapsBackThroughEachFramesCameraPose) {
  constexpr double kMaxSmoothedToRaw = 0.3;  // as for a still tool in `world`
  const Sequence still = Make(300, 0.0, 4);  // world_from_tool, with the tilt noise
  std::vector<std::optional<Rigid3d>> ahat_from_tool(still.measured.size());
  std::vector<std::optional<Rigid3d>> world_from_ahat(still.measured.size());
  std::vector<Eigen::Quaterniond> truth(still.measured.size());
  for (std::size_t i = 0; i < still.measured.size(); ++i) {
    const double t = still.time_s[i];
    const Rigid3d camera(
        Eigen::Quaterniond(Eigen::AngleAxisd(0.25 * std::sin(2.0 * t), Eigen::Vector3d::UnitY())),
        Eigen::Vector3d(30.0 * std::sin(1.3 * t), 0.0, -400.0));
    truth[i] = camera.rotation.conjugate() * still.truth[i];
    if (still.measured[i]) ahat_from_tool[i] = camera.Inverse() * *still.measured[i];
    if (i % 50 != 10) world_from_ahat[i] = camera;  // one frame in 50 without a camera pose
  }
  const std::vector<std::optional<Rigid3d>> raw = ahat_from_tool;
  const std::size_t smoothed = SmoothAhatRotations(ahat_from_tool, world_from_ahat, still.time_s);
  double raw2 = 0.0, smoothed2 = 0.0;
  std::size_t posed = 0;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    if (!raw[i]) continue;
    ++posed;
    EXPECT_EQ(ahat_from_tool[i]->translation, raw[i]->translation) << i;
    if (!world_from_ahat[i]) {
      EXPECT_EQ(ahat_from_tool[i]->rotation.coeffs(), raw[i]->rotation.coeffs()) << i;
      continue;
    }
    raw2 += std::pow(raw[i]->rotation.angularDistance(truth[i]), 2);
    smoothed2 += std::pow(ahat_from_tool[i]->rotation.angularDistance(truth[i]), 2);
  }
  EXPECT_EQ(smoothed, posed - 5);  // less the 6 frames without a camera pose, one of them unposed
  EXPECT_LT(smoothed2, kMaxSmoothedToRaw * kMaxSmoothedToRaw * raw2);
}

}  // namespace
}  // namespace tofnav
