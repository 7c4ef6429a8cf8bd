// SPDX-License-Identifier: BSD-3-Clause
// How well a surface pins down a rigid pose: eigen-analysis of the 6x6 Gauss-Newton information.
#pragma once

#include <Eigen/Core>

#include "tofnav/core/dense_solvers.hpp"

namespace tofnav {

/// Conditioning of J^T J for delta = (omega [rad], v [mm]) with rotation scaled to millimetres at
/// `radius_mm` (so both halves have the same unit) and divided by the correspondence count: an
/// eigenvalue of 1 means one millimetre of motion moves every point one millimetre along its
/// normal. Ratios near 0 mean a direction the surface does not constrain.
struct PoseConditioning {
  Vector6d eigenvalues = Vector6d::Zero();        // ascending, dimensionless
  Vector6d weakest_direction = Vector6d::Zero();  // unit (omega * radius, v) of the smallest
  double overall = 0.0;                           // smallest / largest eigenvalue
  double rotation = 0.0;     // smallest eigenvalue of the rotation block once translation is
                             // optimised away (Schur complement), over the largest eigenvalue
  double translation = 0.0;  // the same for translation, rotation optimised away
};

/// @param information  J^T J with rows [((x - c) x n)^T, n^T] summed over `count` correspondences
PoseConditioning ComputeConditioning(const Matrix6d& information, int count, double radius_mm);

}  // namespace tofnav
