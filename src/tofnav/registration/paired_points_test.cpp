// SPDX-License-Identifier: BSD-3-Clause
// Paired-point registration: exactness, and the Fitzpatrick FRE/TRE relations by Monte Carlo.
#include "tofnav/registration/paired_points.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "matchers.hpp"
#include "registration_scenes.hpp"

namespace tofnav {
namespace {

constexpr double kExactRotRad = 1e-9, kExactTransMm = 1e-9;  // noise-free: exact to round-off
constexpr int kTrials = 3000;            // Monte Carlo trials: expectations within a few percent
constexpr double kMonteCarloTol = 0.06;  // relative, about 3 standard errors at 3000 trials

// Six metal balls on a headframe-sized ring [mm].
const std::vector<Eigen::Vector3d> kFiducials = {{80, 0, 0},  {-80, 0, 10}, {0, 90, -5},
                                                 {0, -90, 5}, {50, 50, 40}, {-40, -60, 30}};

TEST(RegisterPairedPoints, ExactOnNoiseFreePoints) {
  std::mt19937_64 rng(1);
  const Rigid3d truth = test::RandomRigid(rng, 3.0, 200.0);
  std::vector<Eigen::Vector3d> moved;
  for (const Eigen::Vector3d& f : kFiducials) moved.push_back(truth * f);
  const PairedPointResult r = RegisterPairedPoints(kFiducials, moved);
  EXPECT_THAT(r.target_from_source, RigidNear(truth, kExactRotRad, kExactTransMm));
  EXPECT_LT(r.fre_rms_mm, 1e-9);
  EXPECT_EQ(r.residuals_mm.size(), kFiducials.size());
}

TEST(RegisterPairedPoints, RejectsCollinearAndMismatchedInput) {
  const std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  EXPECT_THROW(RegisterPairedPoints(line, line), std::invalid_argument);
  const std::vector<Eigen::Vector3d> two = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_THROW(RegisterPairedPoints(two, two), std::invalid_argument);
  EXPECT_THROW(RegisterPairedPoints(kFiducials, line), std::invalid_argument);
}

TEST(PredictFiducialTreMm, MatchesMonteCarloAndFreRelation) {
  constexpr double kFleRmsMm = 0.5;  // 3-D RMS localisation error
  const double sigma = kFleRmsMm / std::sqrt(3.0);
  const Eigen::Vector3d target(10.0, 20.0, 70.0);  // a deep target beside the fiducials
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, sigma);
  double fre_sq = 0.0, tre_sq = 0.0;
  for (int t = 0; t < kTrials; ++t) {
    std::vector<Eigen::Vector3d> measured;
    for (const Eigen::Vector3d& f : kFiducials) {
      measured.push_back(f + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
    }
    const PairedPointResult r = RegisterPairedPoints(measured, kFiducials);
    fre_sq += r.fre_rms_mm * r.fre_rms_mm;
    tre_sq += (r.target_from_source * target - target).squaredNorm();
  }
  const double n = static_cast<double>(kFiducials.size());
  EXPECT_NEAR(std::sqrt(fre_sq / kTrials) / (kFleRmsMm * std::sqrt(1.0 - 2.0 / n)), 1.0,
              kMonteCarloTol);
  EXPECT_NEAR(std::sqrt(tre_sq / kTrials) / PredictFiducialTreMm(kFiducials, kFleRmsMm, target),
              1.0, kMonteCarloTol);
  EXPECT_NEAR(EstimateFleFromFreMm(kFleRmsMm * std::sqrt(1.0 - 2.0 / n), kFiducials.size()),
              kFleRmsMm, 1e-12);
}

TEST(PredictFiducialTreMm, AtTheCentroidIsFleOverRootN) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& f : kFiducials)
    centroid += f / static_cast<double>(kFiducials.size());
  EXPECT_NEAR(PredictFiducialTreMm(kFiducials, 0.6, centroid),
              0.6 / std::sqrt(static_cast<double>(kFiducials.size())), 1e-12);
}

}  // namespace
}  // namespace tofnav
