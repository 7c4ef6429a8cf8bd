// SPDX-License-Identifier: BSD-3-Clause
// The one instantiation of each Eigen decomposition tofnav uses (dense_solvers.hpp).
#include "tofnav/core/dense_solvers.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "tofnav/core/require.hpp"

namespace tofnav {

SymmetricEigen3 DecomposeSymmetric(const Eigen::Matrix3d& m) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(m);
  return {solver.eigenvalues(), solver.eigenvectors()};
}

SymmetricEigen6 DecomposeSymmetric(const Matrix6d& m) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> solver(m);
  return {solver.eigenvalues(), solver.eigenvectors()};
}

Vector6d SolveSymmetric(const Matrix6d& a, const Vector6d& b) { return a.ldlt().solve(b); }
Matrix6d InvertSymmetric(const Matrix6d& a) { return a.ldlt().solve(Matrix6d::Identity()); }

Eigen::Quaterniond RotationBetween(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  return Eigen::Quaterniond::FromTwoVectors(from, to);
}

PrincipalAxes ComputePrincipalAxes(std::span<const Eigen::Vector3d> points) {
  Require(!points.empty(), "ComputePrincipalAxes: no points");
  PrincipalAxes out;
  out.centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) out.centroid += p;
  out.centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d d = p - out.centroid;
    scatter += d * d.transpose();
  }
  const SymmetricEigen3 eig = DecomposeSymmetric(scatter);
  // n centred points span at most n - 1 dimensions: the spreads beyond are exactly zero.
  const auto rank = static_cast<int>(std::min<std::size_t>(points.size() - 1, 3));
  for (int i = 0; i < 3; ++i) {  // descending
    out.spreads(i) = i < rank ? std::sqrt(std::max(eig.values(2 - i), 0.0)) : 0.0;
    out.axes.col(i) = eig.vectors.col(2 - i);
  }
  return out;
}

}  // namespace tofnav
