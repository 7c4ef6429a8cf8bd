// SPDX-License-Identifier: BSD-3-Clause
// The temporal pose check on synthetic world_from_tool sequences with known jumps.
#include "tofnav/tracking/pose_consistency.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "tofnav/core/require.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/tracking/pose_jump_guard.hpp"

namespace tofnav {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kFrameS = 1.0 / 45.0;  // AHAT frame interval
// Noise of world_from_tool per frame as RMS of the whole vector: HoloLens 2 head tracking
// (~0.5 mm, ~0.1 deg) and the tool's unfiltered tracking (~0.2 mm, ~0.3 deg; docs/tracking.md).
constexpr double kSlamMm = 0.5, kSlamRad = 0.1 * kDeg, kToolMm = 0.2, kToolRad = 0.3 * kDeg;
// A jump is measured against its neighbours' robust centre: within the pose's own jitter (0.54
// mm, 0.32 deg RMS) of the jump plus the centre's (smaller: a median of ~13 neighbours).
constexpr double kJumpTolMm = 0.5, kJumpTolRad = 0.5 * kDeg;

// A headframe drifting slowly in `world` (3 mm/s, 1 deg/s: a patient settling), with jitter
// `slam_mm` RMS in head tracking.
std::vector<std::optional<Rigid3d>> Sequence(int count, std::uint64_t seed,
                                             double slam_mm = kSlamMm) {
  std::mt19937_64 rng(seed);
  const double sigma_mm = std::hypot(slam_mm, kToolMm) / std::sqrt(3.0);  // per axis
  const double sigma_rad = std::hypot(kSlamRad, kToolRad) / std::sqrt(3.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<std::optional<Rigid3d>> poses;
  for (int i = 0; i < count; ++i) {
    const double t = i * kFrameS;
    const Eigen::Vector3d jitter_t(noise(rng), noise(rng), noise(rng));
    const Eigen::Vector3d jitter_r(noise(rng), noise(rng), noise(rng));
    const Eigen::Quaterniond drift(Eigen::AngleAxisd(1.0 * kDeg * t, Eigen::Vector3d::UnitY()));
    const Eigen::Quaterniond jitter(
        Eigen::AngleAxisd(sigma_rad * jitter_r.norm(), jitter_r.normalized()));
    poses.emplace_back(Rigid3d(
        jitter * drift, Eigen::Vector3d(100.0 + 3.0 * t, -50.0, 400.0) + sigma_mm * jitter_t));
  }
  return poses;
}

std::vector<double> Times(int count) {
  std::vector<double> t(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) t[static_cast<std::size_t>(i)] = 1000.0 + i * kFrameS;
  return t;
}

// Four bad poses and a gap: a 5 deg rotation about the tool origin (a wrong marker
// correspondence) at 100, a 4 mm shift at 200, two consecutive 3 deg jumps at 300-301, no pose at
// 350.
void AddJumps(std::vector<std::optional<Rigid3d>>& poses) {
  const Eigen::Quaterniond five(
      Eigen::AngleAxisd(5.0 * kDeg, Eigen::Vector3d(1, 1, 0).normalized()));
  poses[100]->rotation = poses[100]->rotation * five;
  poses[200]->translation += Eigen::Vector3d(0.0, 4.0, 0.0);
  const Eigen::Quaterniond three(Eigen::AngleAxisd(3.0 * kDeg, Eigen::Vector3d::UnitX()));
  poses[300]->rotation = poses[300]->rotation * three;
  poses[301]->rotation = poses[301]->rotation * three;
  poses[350].reset();
}

bool IsAddedJump(int i) { return i == 100 || i == 200 || i == 300 || i == 301; }

TEST(CheckPoseConsistency, FlagsTheJumpsAndNoneOfTheCleanPoses) {
  constexpr int kFrames = 450;  // 10 s
  const std::vector<double> times = Times(kFrames);
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {  // clean sequences: nothing flagged
    const auto poses = Sequence(kFrames, seed);
    const auto results = CheckPoseConsistency(poses, times);
    for (int i = 0; i < kFrames; ++i) {
      EXPECT_EQ(results[static_cast<std::size_t>(i)].status, PoseConsistency::kConsistent)
          << "seed " << seed << " frame " << i;
    }
  }
  auto poses = Sequence(kFrames, 7);
  AddJumps(poses);
  const auto results = CheckPoseConsistency(poses, times);
  for (int i = 0; i < kFrames; ++i) {
    const auto expected = IsAddedJump(i) ? PoseConsistency::kJump
                          : i == 350     ? PoseConsistency::kUnchecked
                                         : PoseConsistency::kConsistent;
    EXPECT_EQ(results[static_cast<std::size_t>(i)].status, expected) << "frame " << i;
  }
  EXPECT_NEAR(results[100].rotation_rad, 5.0 * kDeg, kJumpTolRad);
  EXPECT_NEAR(results[200].translation_mm, 4.0, kJumpTolMm);
}

TEST(CheckPoseConsistency, NoisierHeadTrackingRaisesTheThresholdButNotOverARealJump) {
  constexpr int kFrames = 450;
  constexpr double kNoisySlamMm = 1.7;  // 1 mm per axis: the suite's jitter cases
  const std::vector<double> times = Times(kFrames);
  auto poses = Sequence(kFrames, 3, kNoisySlamMm);
  const Eigen::Quaterniond five(Eigen::AngleAxisd(5.0 * kDeg, Eigen::Vector3d::UnitZ()));
  poses[150]->rotation = poses[150]->rotation * five;
  const auto results = CheckPoseConsistency(poses, times);
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_EQ(results[static_cast<std::size_t>(i)].status,
              i == 150 ? PoseConsistency::kJump : PoseConsistency::kConsistent)
        << "frame " << i << " " << results[static_cast<std::size_t>(i)].translation_mm << " "
        << results[static_cast<std::size_t>(i)].rotation_rad / kDeg;
  }
}

TEST(CheckPoseConsistency, TooFewNeighboursAreUncheckedAndOptionsAreChecked) {
  const auto poses = Sequence(3, 1);
  const std::vector<double> times = Times(3);
  for (const PoseConsistencyResult& r : CheckPoseConsistency(poses, times)) {
    EXPECT_EQ(r.status, PoseConsistency::kUnchecked);
  }
  EXPECT_THROW(CheckPoseConsistency(poses, std::vector<double>(2, 0.0)), PreconditionError);
  PoseConsistencyOptions options;
  options.window_s = 0.0;
  EXPECT_THROW(CheckPoseConsistency(poses, times, options), PreconditionError);
}

// The causal guard (navigate) flags the same poses as the recording's check, one at a time.
TEST(PoseJumpGuard, FlagsTheJumpsAsTheyArriveAndNoneOfTheCleanPoses) {
  constexpr int kFrames = 450;
  const std::vector<double> times = Times(kFrames);
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    PoseJumpGuard guard;
    const auto poses = Sequence(kFrames, seed);
    for (int i = 0; i < kFrames; ++i) {
      const auto k = static_cast<std::size_t>(i);
      EXPECT_NE(guard.Judge(*poses[k], times[k]).status, PoseConsistency::kJump)
          << "seed " << seed << " frame " << i;
    }
  }
  PoseJumpGuard guard;
  auto poses = Sequence(kFrames, 7);
  AddJumps(poses);
  for (int i = 0; i < kFrames; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!poses[k]) continue;
    const PoseConsistencyResult r = guard.Judge(*poses[k], times[k]);
    // The first 4 poses have too few accepted neighbours to be judged.
    const auto expected = IsAddedJump(i) ? PoseConsistency::kJump
                          : i < 4        ? PoseConsistency::kUnchecked
                                         : PoseConsistency::kConsistent;
    EXPECT_EQ(r.status, expected) << "frame " << i;
    // Against the trailing window's centre: the pose's jitter and a lag of half the window's
    // drift (3 mm/s x 0.15 s) on top of the jump.
    if (i == 100) {
      EXPECT_NEAR(r.rotation_rad, 5.0 * kDeg, kJumpTolRad);
    }
    if (i == 200) {
      EXPECT_NEAR(r.translation_mm, 4.0, kJumpTolMm + 0.45);
    }
  }
  EXPECT_EQ(guard.jumps(), 4);
  EXPECT_EQ(guard.restarts(), 0);
}

TEST(PoseJumpGuard, ARealMoveRestartsAfterFiveFramesAndTheMeanAveragesTheNoise) {
  constexpr int kFrames = 450, kMove = 200;
  const std::vector<double> times = Times(kFrames);
  auto poses = Sequence(kFrames, 11);
  for (int i = kMove; i < kFrames; ++i) {  // the headframe bumped by 10 mm for good
    poses[static_cast<std::size_t>(i)]->translation += Eigen::Vector3d(10.0, 0.0, 0.0);
  }
  PoseJumpGuard guard;
  double single2 = 0.0, mean2 = 0.0;
  int n = 0;
  for (int i = 0; i < kFrames; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const PoseConsistencyResult r = guard.Judge(*poses[k], times[k]);
    // Four jumps, the fifth restarts the history (unchecked), then 3 more unchecked poses refill
    // it.
    const auto expected = i >= kMove && i < kMove + 4 ? PoseConsistency::kJump
                          : (i >= kMove + 4 && i <= kMove + 7) || i < 4
                              ? PoseConsistency::kUnchecked
                              : PoseConsistency::kConsistent;
    EXPECT_EQ(r.status, expected) << i;
    if (i < 20 || (i >= kMove && i < kMove + 20)) continue;
    // The held pose: the mean of the last 0.1 s (5 poses) against the noise-free pose. Its lag
    // (half the span of a 3 mm/s drift: 0.15 mm) costs less than the averaging gains.
    const Eigen::Vector3d truth_mm(100.0 + 3.0 * i * kFrameS + (i >= kMove ? 10.0 : 0.0), -50.0,
                                   400.0);
    const std::optional<Rigid3d> mean = guard.Mean(times[k], 0.1);
    ASSERT_TRUE(mean.has_value());
    single2 += (poses[k]->translation - truth_mm).squaredNorm();
    mean2 += (mean->translation - truth_mm).squaredNorm();
    ++n;
  }
  EXPECT_EQ(guard.restarts(), 1);
  EXPECT_EQ(guard.jumps(), 5);
  // 5 poses average the 0.54 mm jitter to 0.24 mm; with the lag ~0.3 mm: below 0.7 of a pose's.
  EXPECT_LT(std::sqrt(mean2 / n), 0.7 * std::sqrt(single2 / n));
  EXPECT_FALSE(guard.Mean(times.back() + 1.0, 0.1).has_value());  // nothing that recent
}

}  // namespace
}  // namespace tofnav
