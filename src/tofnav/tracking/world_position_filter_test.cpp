// SPDX-License-Identifier: BSD-3-Clause
// WorldPositionFilter: a world-fixed point seen by a moving camera whose reported pose jitters.
#include "tofnav/tracking/world_position_filter.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "tofnav/sim/timing.hpp"
#include "tracking_test_tools.hpp"

namespace tofnav {
namespace {

struct Scene {
  double jitter_mm = 0.3;     // rig pose translation error per axis
  double jitter_rad = 3e-4;   // rig pose rotation error per axis
  double along_mm = 0.43;     // measurement noise along the ray (the filter's model at 750 mm)
  double across_mm = 0.12;    // ... and across it, per axis
  double drift_mm_per_s = 0;  // the point's world motion along x
  double jump_at_s = 1e9;     // the point jumps 5 mm along y here
};

struct Outcome {
  double measured_rms_mm = 0.0, fused_rms_mm = 0.0, jitter_sigma_mm = 0.0;
  int fused = 0, gated = 0, resets = 0, gated_after_jump = 0;
};

// 150 frames at the suite's 6.4 Hz (0.156 s) of a point 750 mm in front of the camera.
Outcome Simulate(const Scene& scene, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  WorldPositionFilter filter;
  RigJitterEstimate jitter;
  const Eigen::Vector3d start_in_world(20.0, -10.0, 750.0);
  Outcome run;
  double measured2 = 0.0, fused2 = 0.0;
  for (int i = 0; i < 150; ++i) {
    const double t = 0.156 * i;
    Eigen::Vector3d in_world = start_in_world + Eigen::Vector3d(scene.drift_mm_per_s * t, 0, 0);
    if (t >= scene.jump_at_s) in_world.y() += 5.0;
    const Rigid3d true_world_from_ahat = testing::TurningCamera(t);
    const Eigen::Vector3d truth = true_world_from_ahat.Inverse() * in_world;
    const Eigen::Vector3d measured =
        truth + testing::RayNoise(truth, scene.along_mm, scene.across_mm, rng);
    const Rigid3d reported = sim::JitterPose(
        true_world_from_ahat,
        {.translation_sigma_mm = scene.jitter_mm, .rotation_sigma_rad = scene.jitter_rad}, rng);
    const WorldPositionUpdate update = filter.Update(
        {.measured_in_ahat = measured, .estimate_in_ahat = measured}, reported, t, jitter);
    run.gated += update.gated;
    run.resets += update.reset;
    if (t >= scene.jump_at_s && t < scene.jump_at_s + 1.0) run.gated_after_jump += update.gated;
    if (i < 20 || !update.fused_in_ahat) continue;
    measured2 += (measured - truth).squaredNorm();
    fused2 += (*update.fused_in_ahat - truth).squaredNorm();
    ++run.fused;
  }
  run.measured_rms_mm = std::sqrt(measured2 / std::max(1, run.fused));
  run.fused_rms_mm = std::sqrt(fused2 / std::max(1, run.fused));
  run.jitter_sigma_mm = std::sqrt(jitter.variance_mm2());
  return run;
}

// The rig pose's error and the measurement's are independent, so the fusion beats the
// measurement (and the rig pose, 0.38 mm per axis here, 0.65 in 3D): along the ray the
// prediction is the better of the two, across it the measurement. At best (known jitter, a
// converged world position) 0.30 against 0.46 mm: a ratio of 0.64.
TEST(WorldPositionFilter, FusesAStillPointBetterThanTheMeasurementOrTheRigPose) {
  constexpr double kMaxFusedToMeasuredRatio = 0.8;  // the jitter is estimated, the state wanders
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const Outcome run = Simulate({}, seed);
    EXPECT_GE(run.fused, 125) << seed;
    EXPECT_LT(run.fused_rms_mm, kMaxFusedToMeasuredRatio * run.measured_rms_mm) << seed;
    EXPECT_LE(run.resets, 1) << seed;  // the start only
  }
}

// The jitter estimate comes from the innovations across the ray: per axis at the tool it is
// sqrt(jitter_mm^2 + (jitter_rad * 750 mm)^2): 0.38 mm for the simulator's default, 1.25 for
// its jittery cases (1 mm, 1e-3 rad). Within 25 %: a running mean over ~32 noisy samples.
TEST(WorldPositionFilter, MeasuresTheRigPosesJitterFromTheInnovations) {
  constexpr double kTolerance = 0.25;  // relative
  for (const double scale : {1.0, 10.0 / 3.0}) {
    Scene scene;
    scene.jitter_mm *= scale;
    scene.jitter_rad *= scale;
    const double expected = std::hypot(scene.jitter_mm, scene.jitter_rad * 750.0);
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      const Outcome run = Simulate(scene, seed);
      EXPECT_NEAR(run.jitter_sigma_mm, expected, kTolerance * expected) << scale << " " << seed;
      // With a jittery rig pose the prediction is worth little; the fusion must not hurt.
      EXPECT_LT(run.fused_rms_mm, run.measured_rms_mm) << scale << " " << seed;
    }
  }
}

// A patient whose head drifts 1 mm/s (the simulator's drift) is followed; a 5 mm move is gated
// and restarts the filter within max_gated frames, after which it fuses again.
TEST(WorldPositionFilter, FollowsADriftingPatientAndRestartsAfterAMove) {
  Scene scene;
  scene.drift_mm_per_s = 1.0;
  scene.jump_at_s = 12.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const Outcome run = Simulate(scene, seed);
    EXPECT_LT(run.fused_rms_mm, 0.85 * run.measured_rms_mm) << seed;
    EXPECT_GE(run.gated_after_jump, 1) << seed;
    EXPECT_LE(run.gated_after_jump, 3) << seed;
    EXPECT_EQ(run.resets, 2) << seed;  // the start and the move
    EXPECT_GE(run.fused, 110) << seed;
  }
}

// Two plates of one headframe, 220 mm apart, 700 mm in front of the camera: one rig pose
// places both, so each frame's rig error is (nearly) the same at both. Fused with that error
// shared, each plate's position gains the other's innovation: at best, with the along-ray noise
// (0.39 mm at 700 mm) about the rig error's (0.37 mm per axis), the along-ray variance falls
// from 1/(1/a + 1/j) to 1/(1/a + 2/(a + j))-ish, about 15 % in RMS over all three axes; the
// rotation part of the rig error (3e-4 rad x 220 mm = 0.07 mm) differs between them. Bound:
// 0.95 of the independent fusions' RMS, pooled over 4 seeds (one seed's 130 frames per plate
// wander by a few per cent).
TEST(FuseWithSharedRigError, TwoPlatesOfOneRigPoseBeatEachFusedAlone) {
  constexpr double kMaxSharedToAloneRatio = 0.95;
  const std::array<Eigen::Vector3d, 2> in_world = {Eigen::Vector3d(110.0, 0.0, 700.0),
                                                   Eigen::Vector3d(-110.0, 0.0, 700.0)};
  double alone2 = 0.0, shared2 = 0.0;
  int count = 0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    std::mt19937_64 rng(seed);
    std::array<WorldPositionFilter, 2> filters;
    RigJitterEstimate jitter;
    for (int i = 0; i < 150; ++i) {
      const double t = 0.156 * i;
      const Rigid3d true_world_from_ahat = testing::TurningCamera(t);
      const Rigid3d reported = sim::JitterPose(
          true_world_from_ahat, {.translation_sigma_mm = 0.3, .rotation_sigma_rad = 3e-4}, rng);
      std::vector<WorldPointTerms> terms;
      std::vector<Eigen::Vector3d> alone, truths;
      for (std::size_t k = 0; k < 2; ++k) {
        const Eigen::Vector3d truth = true_world_from_ahat.Inverse() * in_world[k];
        const Eigen::Vector3d measured = truth + testing::RayNoise(truth, 0.39, 0.10, rng);
        const WorldPositionUpdate update = filters[k].Update(
            {.measured_in_ahat = measured, .estimate_in_ahat = measured}, reported, t, jitter);
        if (!update.fused_in_ahat) continue;
        terms.push_back(*update.terms);
        alone.push_back(*update.fused_in_ahat);
        truths.push_back(truth);
      }
      if (i < 20 || terms.size() != 2) continue;
      std::vector<bool> joined;
      const std::vector<Eigen::Vector3d> shared =
          FuseWithSharedRigError(terms, jitter.variance_mm2(), 16.27, &joined);
      for (std::size_t k = 0; k < 2; ++k) {
        EXPECT_TRUE(joined[k]) << seed << " " << i;
        alone2 += (alone[k] - truths[k]).squaredNorm();
        shared2 += (shared[k] - truths[k]).squaredNorm();
        ++count;
      }
    }
  }
  ASSERT_GE(count, 4 * 2 * 120);
  const double alone_rms = std::sqrt(alone2 / count), shared_rms = std::sqrt(shared2 / count);
  std::printf("shared rig error: %.3f mm RMS against %.3f fused alone (%d plate-frames)\n",
              shared_rms, alone_rms, count);
  EXPECT_LT(shared_rms, kMaxSharedToAloneRatio * alone_rms);
}

// One point is its own fusion; a point whose innovation disagrees with the others' shared error
// (a tool that moved, 5 mm here against 0.4 mm of noise) is fused alone and leaves the others'
// fusion as if it were not there.
TEST(FuseWithSharedRigError, FusesAPointThatDisagreesAlone) {
  const auto point = [](const Eigen::Vector3d& predicted, const Eigen::Vector3d& estimate) {
    return WorldPointTerms{.predicted_in_ahat = predicted,
                           .held_cov_mm2 = 0.01 * Eigen::Matrix3d::Identity(),
                           .estimate_in_ahat = estimate,
                           .estimate_cov_mm2 = 0.09 * Eigen::Matrix3d::Identity()};
  };
  const WorldPointTerms a = point({100, 0, 600}, {100.2, 0.1, 600.3});
  const WorldPointTerms b = point({-100, 0, 600}, {-99.9, 0.2, 600.2});
  const WorldPointTerms moved = point({0, 50, 600}, {5.0, 50.0, 600.0});
  const double rig = 0.12;
  const std::vector<WorldPointTerms> two = {a, b}, three = {a, b, moved};
  std::vector<bool> joined;
  const std::vector<Eigen::Vector3d> with_two = FuseWithSharedRigError(two, rig, 16.27);
  const std::vector<Eigen::Vector3d> with_three =
      FuseWithSharedRigError(three, rig, 16.27, &joined);
  EXPECT_EQ(joined, (std::vector<bool>{true, true, false}));
  EXPECT_LT((with_three[0] - with_two[0]).norm(), 1e-12);
  EXPECT_LT((with_three[1] - with_two[1]).norm(), 1e-12);
  const std::vector<WorldPointTerms> alone = {moved};
  EXPECT_LT((with_three[2] - FuseWithSharedRigError(alone, rig, 16.27)[0]).norm(), 1e-12);
  // The shared fusion is Gaussian conditioning: with equal terms and the same innovation the
  // two points' offsets from their predictions are equal, and smaller than the innovation.
  const std::vector<WorldPointTerms> same = {point({0, 0, 600}, {0, 0, 600.4}),
                                             point({50, 0, 600}, {50, 0, 600.4})};
  const std::vector<Eigen::Vector3d> fused = FuseWithSharedRigError(same, rig, 16.27);
  EXPECT_NEAR(fused[0].z() - 600.0, fused[1].z() - 600.0, 1e-12);
  EXPECT_GT(fused[0].z() - 600.0, 0.0);
  EXPECT_LT(fused[0].z() - 600.0, 0.4);
  EXPECT_THROW(FuseWithSharedRigError(same, 0.0, 16.27), std::invalid_argument);
}

TEST(WorldPositionFilter, RefusesBadOptions) {
  WorldPositionOptions bad;
  bad.min_jitter_sigma_mm = 0.0;
  EXPECT_THROW(WorldPositionFilter{bad}, std::invalid_argument);
  bad = {};
  bad.max_gated = 0;
  EXPECT_THROW(RigJitterEstimate{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
