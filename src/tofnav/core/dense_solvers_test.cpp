// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/core/dense_solvers.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace tofnav {
namespace {

// Double rounding on values of order 1-100: 1e-9 leaves room for the iterative solvers.
constexpr double kTol = 1e-9;

TEST(DenseSolvers, DecomposeSymmetricReconstructsTheMatrix) {
  Matrix6d a = Matrix6d::Random();
  a = (a * a.transpose()).eval() + Matrix6d::Identity();
  const SymmetricEigen6 e = DecomposeSymmetric(a);
  for (int i = 0; i + 1 < 6; ++i) EXPECT_LE(e.values(i), e.values(i + 1));  // ascending
  EXPECT_LT((e.vectors * e.values.asDiagonal() * e.vectors.transpose() - a).norm(), kTol);
  const Eigen::Matrix3d b = a.topLeftCorner<3, 3>();
  const SymmetricEigen3 f = DecomposeSymmetric(b);
  EXPECT_LT((f.vectors * f.values.asDiagonal() * f.vectors.transpose() - b).norm(), kTol);
}

TEST(DenseSolvers, SolveSymmetricSolves) {
  Matrix6d a = Matrix6d::Random();
  a = (a * a.transpose()).eval() + Matrix6d::Identity();
  const Vector6d x = Vector6d::LinSpaced(-2.0, 3.0);
  EXPECT_LT((SolveSymmetric(a, a * x) - x).norm(), kTol);
}

TEST(DenseSolvers, RotationBetweenMapsTheDirections) {
  const Eigen::Vector3d from(1.0, 2.0, -0.5), to(-3.0, 0.2, 1.0);
  const Eigen::Quaterniond q = RotationBetween(from, to);
  EXPECT_LT((q * from.normalized() - to.normalized()).norm(), kTol);
  // Opposite directions: a half turn.
  EXPECT_LT((RotationBetween(from, -from) * from + from).norm(), kTol);
}

TEST(DenseSolvers, PrincipalAxesOfABox) {
  // Points at +-a x, +-b y, +-c z around (10, 20, 30): spreads sqrt(2) a, b, c in that order.
  const Eigen::Vector3d c(10.0, 20.0, 30.0);
  std::vector<Eigen::Vector3d> p;
  for (const double s : {-1.0, 1.0}) {
    p.push_back(c + s * Eigen::Vector3d(0.0, 5.0, 0.0));
    p.push_back(c + s * Eigen::Vector3d(0.0, 0.0, 1.0));
    p.push_back(c + s * Eigen::Vector3d(40.0, 0.0, 0.0));
  }
  const PrincipalAxes axes = ComputePrincipalAxes(p);
  EXPECT_LT((axes.centroid - c).norm(), kTol);
  EXPECT_NEAR(axes.spreads(0), std::sqrt(2.0) * 40.0, kTol);
  EXPECT_NEAR(axes.spreads(1), std::sqrt(2.0) * 5.0, kTol);
  EXPECT_NEAR(axes.spreads(2), std::sqrt(2.0) * 1.0, kTol);
  EXPECT_NEAR(std::abs(axes.axes.col(0).x()), 1.0, kTol);
  EXPECT_NEAR(std::abs(axes.axes.col(1).y()), 1.0, kTol);
  // Three points span a plane: the third spread is exactly zero.
  const std::vector<Eigen::Vector3d> three(p.begin(), p.begin() + 3);
  EXPECT_EQ(ComputePrincipalAxes(three).spreads(2), 0.0);
}

}  // namespace
}  // namespace tofnav
