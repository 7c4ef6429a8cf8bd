// SPDX-License-Identifier: BSD-3-Clause
// A small Levenberg-Marquardt for a few parameters with central-difference Jacobians.
#pragma once

#include <Eigen/Core>
#include <functional>

namespace tofnav {

struct LevenbergMarquardtOptions {
  int max_iterations = 30;
  double initial_damping = 1e-3;  // lambda, relative to diag(J^T J) (Marquardt scaling)
  /// Stop when a step lowers the cost by less than this fraction, or when every parameter moves
  /// by less than relative_step_tolerance of its difference step.
  double relative_cost_tolerance = 1e-9;
  double relative_step_tolerance = 1e-3;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

struct LevenbergMarquardtResult {
  Eigen::VectorXd parameters;
  double initial_cost = 0.0;  // 0.5 |r|^2 at the start
  double final_cost = 0.0;
  int iterations = 0;
  int evaluations = 0;
  Eigen::MatrixXd information;      // J^T J at the solution
  Eigen::VectorXd standard_errors;  // sqrt(diag((J^T J)^-1) 2 F / (m - n)), NaN when singular
};

/// Minimises 0.5 |r(x)|^2 over x. The residual vector must keep its size. `difference_steps`
/// (one per parameter, > 0) set the central differences of the Jacobian: choose them above the
/// noise of r (e.g. an inner ICP's tolerance), in each parameter's unit.
LevenbergMarquardtResult MinimiseLeastSquares(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& residuals,
    const Eigen::VectorXd& start, const Eigen::VectorXd& difference_steps,
    const LevenbergMarquardtOptions& options = {});

}  // namespace tofnav
