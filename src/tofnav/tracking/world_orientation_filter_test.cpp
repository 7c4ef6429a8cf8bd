// SPDX-License-Identifier: BSD-3-Clause
// WorldOrientationFilter: a patient-fixed tool that stands still in `world`, turns, and stands
// still again, seen with a far plate's orientation noise.
#include "tofnav/tracking/world_orientation_filter.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

#include "tofnav/core/rotation_vector.hpp"

namespace tofnav {
namespace {

constexpr double kDegPerRad = 180.0 / 3.141592653589793;

struct Motion {
  double rate_hz = 6.4;         // the suite's sampled rate; 45 for a full-rate recording
  double sigma_rad = 0.0069;    // per axis: a disc plate at 600 mm (docs/tracking.md 1)
  double turn_deg_per_s = 2.0;  // the patient turns the head at this rate ...
  double turn_start_s = 20.0;   // ... from here
  double turn_s = 3.0;          // ... for this long, then stands still again
  double duration_s = 35.0;
};

struct Outcome {
  double still_rms_deg = 0.0;   // before the turn and from 5 s after it (warm-up left out)
  double worst_turn_deg = 0.0;  // while turning and in the 5 s after
};

Outcome Simulate(const Motion& m, WorldOrientationOptions options, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, m.sigma_rad);
  options.rotation_sigma_rad = m.sigma_rad;
  WorldOrientationFilter filter(options);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, 1.0, 0.2).normalized();
  const Eigen::Quaterniond start(
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1.0, 0.2, -0.3).normalized()));
  Outcome out;
  double still2 = 0.0;
  int still = 0;
  const int frames = static_cast<int>(m.duration_s * m.rate_hz);
  for (int i = 0; i < frames; ++i) {
    const double t = i / m.rate_hz;
    const double angle =
        m.turn_deg_per_s / kDegPerRad * std::clamp(t - m.turn_start_s, 0.0, m.turn_s);
    const Eigen::Quaterniond truth = Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis)) * start;
    const Eigen::Quaterniond measured =
        FromRotationVector({noise(rng), noise(rng), noise(rng)}) * truth;
    const WorldOrientationUpdate u = filter.Update(measured, t);
    const double error_deg = RotationVector(u.filtered * truth.inverse()).norm() * kDegPerRad;
    const double after_turn_s = t - (m.turn_start_s + m.turn_s);
    if (t >= m.turn_start_s && after_turn_s < 5.0) {
      out.worst_turn_deg = std::max(out.worst_turn_deg, error_deg);
    } else if (t >= 3.0) {
      still2 += error_deg * error_deg;
      ++still;
    }
  }
  out.still_rms_deg = std::sqrt(still2 / still);
  return out;
}

// Against the turning model alone (the world filter of sessions 20-53), with the noise model
// right: a still tool is averaged as the still model would, a turn costs a few frames more
// before the turning model takes over. Measured (20 seeds): still 0.165 / 0.072 deg RMS against
// 0.219 / 0.092 at 6.4 / 45 Hz; worst while and after a 2 deg/s turn 2.65 / 1.42 deg against
// 2.17 / 1.39 (docs/tracking.md 1, "The orientation held in the world").
TEST(WorldOrientationFilter, AveragesAStillToolAndFollowsATurn) {
  constexpr double kMaxStillRatio = 0.85;  // the still spells' RMS against the turning model's
  constexpr double kMaxTurnRatio = 1.3;    // the worst error of a turn against the same
  WorldOrientationOptions turning_only;
  turning_only.still_sigma_rad_per_s = 0.0;
  const WorldOrientationOptions mixed;
  for (const double rate_hz : {6.4, 45.0}) {
    Motion m;
    m.rate_hz = rate_hz;
    double mixed_still2 = 0.0, single_still2 = 0.0, mixed_worst = 0.0, single_worst = 0.0;
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      const Outcome a = Simulate(m, mixed, seed), b = Simulate(m, turning_only, seed);
      mixed_still2 += a.still_rms_deg * a.still_rms_deg;
      single_still2 += b.still_rms_deg * b.still_rms_deg;
      mixed_worst = std::max(mixed_worst, a.worst_turn_deg);
      single_worst = std::max(single_worst, b.worst_turn_deg);
    }
    std::printf(
        "%.1f Hz: still %.3f deg RMS (the turning model alone %.3f), worst of a turn %.3f (%.3f)\n",
        rate_hz, std::sqrt(mixed_still2 / 20), std::sqrt(single_still2 / 20), mixed_worst,
        single_worst);
    EXPECT_LT(mixed_still2, kMaxStillRatio * kMaxStillRatio * single_still2) << rate_hz << " Hz";
    EXPECT_LT(mixed_worst, kMaxTurnRatio * single_worst) << rate_hz << " Hz";
  }
}

// A patient moved 10 deg at once: gated twice, then the filter starts again from the new pose.
TEST(WorldOrientationFilter, RestartsAfterAJump) {
  WorldOrientationFilter filter;
  const Eigen::Quaterniond still = Eigen::Quaterniond::Identity();
  for (int i = 0; i < 30; ++i) EXPECT_FALSE(filter.Update(still, i / 45.0).gated);
  const Eigen::Quaterniond moved = FromRotationVector({0.0, 10.0 / kDegPerRad, 0.0});
  const WorldOrientationUpdate first = filter.Update(moved, 30 / 45.0);
  const WorldOrientationUpdate second = filter.Update(moved, 31 / 45.0);
  const WorldOrientationUpdate third = filter.Update(moved, 32 / 45.0);
  EXPECT_TRUE(first.gated && second.gated);
  EXPECT_LT(RotationVector(first.filtered).norm(), 1e-9);  // the held orientation while gated
  EXPECT_TRUE(third.reset);
  EXPECT_LT(RotationVector(third.filtered * moved.inverse()).norm(), 1e-12);
  EXPECT_GT(filter.Update(moved, 33 / 45.0).still_probability, 0.9);
}

// The variance the filter reports is the one its estimate has: a still tool seen from its first
// frame, over 400 noise seeds, has an angle error whose RMS at frame k is sqrt(3 * ratio_k) times
// the per-axis noise, at the first frame (ratio 1), while it averages, and held still for long.
// 400 seeds put the RMS's own sampling error near 2.5 %: within 10 % over the first ten frames
// (measured 0.98-1.03), and never more than 10 % optimistic. Held still for long it over-states
// the error by about 12 % (measured 0.87-0.90 from frame 19): the turning model keeps a share and
// its variance stays larger than the mixture's error; up to 20 % is allowed there.
TEST(WorldOrientationFilter, ItsVarianceRatioIsTheErrorItHas) {
  constexpr double kTolerance = 0.10, kConservative = 0.20;
  constexpr int kSeeds = 400;
  const std::vector<int> frames_checked = {0, 1, 2, 4, 9, 19, 63};
  const Motion m;  // 6.4 Hz, 0.0069 rad per axis; stands still over the frames checked
  std::vector<double> error2(frames_checked.size(), 0.0), ratio(frames_checked.size(), 0.0);
  for (int seed = 1; seed <= kSeeds; ++seed) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
    std::normal_distribution<double> noise(0.0, m.sigma_rad);
    WorldOrientationOptions options;
    options.rotation_sigma_rad = m.sigma_rad;
    WorldOrientationFilter filter(options);
    const Eigen::Quaterniond truth(
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 1.0, -0.4).normalized()));
    for (int i = 0, c = 0; i <= frames_checked.back(); ++i) {
      const Eigen::Quaterniond measured =
          FromRotationVector({noise(rng), noise(rng), noise(rng)}) * truth;
      const WorldOrientationUpdate u = filter.Update(measured, i / m.rate_hz);
      if (i != frames_checked[static_cast<std::size_t>(c)]) continue;
      error2[static_cast<std::size_t>(c)] +=
          RotationVector(u.filtered * truth.inverse()).squaredNorm();
      ratio[static_cast<std::size_t>(c)] += u.variance_ratio;
      ++c;
    }
  }
  for (std::size_t c = 0; c < frames_checked.size(); ++c) {
    const double rms = std::sqrt(error2[c] / kSeeds);
    const double expected = std::sqrt(3.0 * ratio[c] / kSeeds) * m.sigma_rad;
    std::printf("frame %d: error %.3f deg RMS, the filter's %.3f\n", frames_checked[c],
                rms * kDegPerRad, expected * kDegPerRad);
    const double low = frames_checked[c] < 10 ? 1.0 - kTolerance : 1.0 - kConservative;
    EXPECT_GE(rms / expected, low) << "frame " << frames_checked[c];
    EXPECT_LE(rms / expected, 1.0 + kTolerance) << "frame " << frames_checked[c];
  }
}

TEST(WorldOrientationFilter, RefusesBadOptions) {
  WorldOrientationOptions o;
  o.still_dwell_s = 0.0;
  EXPECT_THROW(WorldOrientationFilter{o}, std::invalid_argument);
  o = {};
  o.still_sigma_rad_per_s = -1e-4;
  EXPECT_THROW(WorldOrientationFilter{o}, std::invalid_argument);
  WorldOrientationFilter filter;
  EXPECT_THROW(filter.Update(Eigen::Quaterniond::Identity(), 0.0, 0.5), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
