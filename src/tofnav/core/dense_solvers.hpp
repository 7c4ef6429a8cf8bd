// SPDX-License-Identifier: BSD-3-Clause
// Eigen's dense decompositions behind plain functions. Eigen's solvers are templates that each
// file using them would instantiate and optimise again (most of such a file's compile time:
// docs/benchmarks.md, "Build"); here they are compiled once, and every caller gets the same code.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <span>

namespace tofnav {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

/// Eigen-decomposition of a symmetric matrix: eigenvalues ascending, eigenvectors as the columns
/// in the same order (Eigen::SelfAdjointEigenSolver, the iterative QL method).
struct SymmetricEigen3 {
  Eigen::Vector3d values;
  Eigen::Matrix3d vectors;
};
struct SymmetricEigen6 {
  Vector6d values;
  Matrix6d vectors;
};
SymmetricEigen3 DecomposeSymmetric(const Eigen::Matrix3d& m);
SymmetricEigen6 DecomposeSymmetric(const Matrix6d& m);

/// x with a x = b for a symmetric positive (semi-)definite `a` (Eigen's LDLT with pivoting).
Vector6d SolveSymmetric(const Matrix6d& a, const Vector6d& b);
/// The inverse of a symmetric positive definite `a` from one such factorisation.
Matrix6d InvertSymmetric(const Matrix6d& a);

/// The smallest rotation taking direction `from` to direction `to` (Eigen's FromTwoVectors; any
/// half turn about an axis perpendicular to both when they are opposite).
Eigen::Quaterniond RotationBetween(const Eigen::Vector3d& from, const Eigen::Vector3d& to);

/// Principal axes of a point set: the centroid, the spreads (root of the sum of squared
/// distances from the centroid along each axis, i.e. the singular values of the centred points;
/// descending) and the axes as the columns in the same order. Computed from the 3 x 3 scatter
/// matrix, so a spread below ~1e-8 of the largest is at rounding level (those beyond the n - 1
/// dimensions that n points span are exactly 0).
struct PrincipalAxes {
  Eigen::Vector3d centroid;
  Eigen::Vector3d spreads;
  Eigen::Matrix3d axes;
};
PrincipalAxes ComputePrincipalAxes(std::span<const Eigen::Vector3d> points);

}  // namespace tofnav
