// SPDX-License-Identifier: BSD-3-Clause
// Internal to registration/: the point-to-plane Jacobian row and the se(3) update shared by the
// ICP and the coarse refinement (Chen & Medioni 1992).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/core/rotation_vector.hpp"
#include "tofnav/registration/pose_conditioning.hpp"

namespace tofnav {

/// Normal equations H = sum w J^T J, g = sum w J^T r of point-to-plane rows about a centre,
/// accumulated with plain scalars (the per-point loop of every ICP; fast unoptimised too).
struct PointToPlaneSums {
  double h[6][6] = {};  // upper triangle
  double g[6] = {};
  int count = 0;

  /// One correspondence: moved source point x, target normal n, residual n . (x - q), weight.
  /// Its Jacobian under x -> exp(omega) (x - c) + c + v is the row [((x - c) x n)^T, n^T].
  void Add(const double* x, const double* n, const double* centre, double residual_mm,
           double weight) {
    const double p[3] = {x[0] - centre[0], x[1] - centre[1], x[2] - centre[2]};
    const double row[6] = {p[1] * n[2] - p[2] * n[1],
                           p[2] * n[0] - p[0] * n[2],
                           p[0] * n[1] - p[1] * n[0],
                           n[0],
                           n[1],
                           n[2]};
    for (int a = 0; a < 6; ++a) {
      const double w_row = weight * row[a];
      g[a] += w_row * residual_mm;
      for (int b = a; b < 6; ++b) h[a][b] += w_row * row[b];
    }
    ++count;
  }
  void Add(const PointToPlaneSums& other) {
    for (int a = 0; a < 6; ++a) {
      g[a] += other.g[a];
      for (int b = a; b < 6; ++b) h[a][b] += other.h[a][b];
    }
    count += other.count;
  }
  Matrix6d Hessian() const {
    Matrix6d m;
    for (int a = 0; a < 6; ++a) {
      for (int b = a; b < 6; ++b) m(a, b) = m(b, a) = h[a][b];
    }
    return m;
  }
  Vector6d Gradient() const { return Vector6d(g[0], g[1], g[2], g[3], g[4], g[5]); }
};

/// exp(delta) about `centre`, applied on the left of `pose`: x -> R(omega) (x - c) + c + v.
inline Rigid3d UpdateOnLeft(const Vector6d& delta, const Eigen::Vector3d& centre,
                            const Rigid3d& pose) {
  const Eigen::Quaterniond turn = FromRotationVector(delta.head<3>());
  return Rigid3d(turn, centre + delta.tail<3>() - (turn * centre)) * pose;
}

}  // namespace tofnav
