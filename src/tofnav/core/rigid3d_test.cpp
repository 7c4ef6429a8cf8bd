// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/core/rigid3d.hpp"

#include <gtest/gtest.h>

#include <random>

#include "matchers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/core/rotation_vector.hpp"

namespace tofnav {
namespace {

constexpr double kExactRotTolRad = 1e-12;  // pure double arithmetic on unit quaternions
constexpr double kExactTransTolMm = 1e-9;

Rigid3d RandomRigid(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return {q.normalized(), Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * 100.0};
}

TEST(Rigid3d, InverseComposesToIdentity) {
  std::mt19937_64 rng(1);
  for (int i = 0; i < 100; ++i) {
    const Rigid3d b_from_a = RandomRigid(rng);
    EXPECT_THAT(b_from_a * b_from_a.Inverse(),
                RigidNear(Rigid3d::Identity(), kExactRotTolRad, kExactTransTolMm));
  }
}

TEST(Rigid3d, CompositionMatchesMatrixProduct) {
  std::mt19937_64 rng(2);
  const Rigid3d c_from_b = RandomRigid(rng);
  const Rigid3d b_from_a = RandomRigid(rng);
  const Eigen::Vector3d p_in_a(12.0, -3.5, 400.0);
  const Eigen::Vector4d expected = c_from_b.ToMatrix() * b_from_a.ToMatrix() * p_in_a.homogeneous();
  EXPECT_LT(((c_from_b * b_from_a) * p_in_a - expected.head<3>()).norm(), kExactTransTolMm);
  EXPECT_LT((c_from_b * (b_from_a * p_in_a) - expected.head<3>()).norm(), kExactTransTolMm);
}

TEST(Rigid3d, MatrixRoundTrip) {
  std::mt19937_64 rng(3);
  const Rigid3d t = RandomRigid(rng);
  EXPECT_THAT(Rigid3d::FromMatrix(t.ToMatrix()), RigidNear(t, 1e-9, kExactTransTolMm));
}

TEST(Rigid3d, KnownTranslationLandsInLastColumn) {
  const Rigid3d t(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(t.ToMatrix()(0, 3), 1.0);
  EXPECT_EQ(t.ToMatrix()(2, 3), 3.0);
  EXPECT_EQ((t * Eigen::Vector3d::Zero()), Eigen::Vector3d(1, 2, 3));
}

TEST(Rigid3d, FromMatrixRejectsScalingAndReflection) {
  Eigen::Matrix4d scaled = Eigen::Matrix4d::Identity();
  scaled(0, 0) = 1.1;
  EXPECT_THROW(Rigid3d::FromMatrix(scaled), PreconditionError);
  Eigen::Matrix4d reflected = Eigen::Matrix4d::Identity();
  reflected(2, 2) = -1.0;
  EXPECT_THROW(Rigid3d::FromMatrix(reflected), PreconditionError);
}

// The rotation vector of either quaternion sign is the short way round (angle <= pi), and
// FromRotationVector inverts it.
TEST(RotationVector, RoundTripsAndTakesTheShortWayRound) {
  std::mt19937_64 rng(3);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Quaterniond q = RandomRigid(rng).rotation;
    const Eigen::Vector3d v = RotationVector(q);
    EXPECT_LE(v.norm(), 3.141592653589793 + kExactRotTolRad);
    EXPECT_EQ(RotationVector(Eigen::Quaterniond(-q.coeffs())), v);
    EXPECT_LT(FromRotationVector(v).angularDistance(q), 1e-9);
  }
  // Exact however small the angle (an ICP's last steps on a symmetric surface are that small,
  // and dropping them changes what the registration's ambiguity test sees); identity at 0 only.
  const Eigen::Vector3d small(1e-13, 0.0, 0.0);
  EXPECT_DOUBLE_EQ(FromRotationVector(small).x(), 5e-14);
  EXPECT_EQ(FromRotationVector(Eigen::Vector3d::Zero()).coeffs(),
            Eigen::Quaterniond::Identity().coeffs());
  EXPECT_NEAR(RotationVector(FromRotationVector({0.0, 0.2, 0.0})).y(), 0.2, kExactRotTolRad);
}

TEST(Require, MessageNamesCallerAndReason) {
  try {
    Require(false, "voxel_size_mm must be positive");
    FAIL() << "Require did not throw";
  } catch (const PreconditionError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("rigid3d_test.cpp"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("voxel_size_mm must be positive"));
  }
}

}  // namespace
}  // namespace tofnav
