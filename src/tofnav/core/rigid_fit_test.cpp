// SPDX-License-Identifier: BSD-3-Clause
// Kabsch fit: exact recovery, reflection safety, degeneracy evidence.
#include "tofnav/core/rigid_fit.hpp"

#include <gtest/gtest.h>

#include <random>

#include "matchers.hpp"
#include "tofnav/core/point_cloud.hpp"

namespace tofnav {
namespace {

constexpr double kExactRad = 1e-9, kExactMm = 1e-9;  // noise-free: rounding only

Points3d RandomPoints(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> u(-80.0, 80.0);
  Points3d p;
  for (int i = 0; i < n; ++i) p.emplace_back(u(rng), u(rng), u(rng));
  return p;
}

TEST(FitRigid, RecoversARandomTransformExactly) {
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    const Points3d source = RandomPoints(rng, 3 + trial % 5);
    const Rigid3d truth(Eigen::Quaterniond::UnitRandom(), Eigen::Vector3d(10.0, -40.0, 500.0));
    Points3d target;
    for (const Eigen::Vector3d& p : source) target.push_back(truth * p);
    const RigidFitResult r = FitRigid(source, target);
    EXPECT_THAT(r.target_from_source, RigidNear(truth, kExactRad, kExactMm));
    EXPECT_LT(r.fre_rms_mm, 1e-9);
    EXPECT_EQ(r.residuals_mm.size(), source.size());
  }
}

TEST(FitRigid, NeverReturnsAReflectionAndReportsPlanarity) {
  const Points3d source = {{0, 0, 0}, {50, 0, 10}, {0, 60, 20}, {30, 30, 70}};
  Points3d mirrored;
  for (const Eigen::Vector3d& p : source) mirrored.emplace_back(-p.x(), p.y(), p.z());
  const RigidFitResult r = FitRigid(source, mirrored);
  EXPECT_NEAR(r.target_from_source.RotationMatrix().determinant(), 1.0, 1e-12);
  EXPECT_GT(r.fre_rms_mm, 5.0);  // a non-planar tool cannot be fitted onto its mirror image
  const Points3d planar = {{0, 0, 0}, {50, 0, 0}, {0, 60, 0}, {30, 30, 0}};
  EXPECT_LT(FitRigid(planar, planar).singular_values[2], 1e-9);
  EXPECT_THROW(FitRigid(Points3d(2, Eigen::Vector3d::Zero()), Points3d(2, Eigen::Vector3d::Zero())),
               std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
