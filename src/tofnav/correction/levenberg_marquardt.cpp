// SPDX-License-Identifier: BSD-3-Clause
// A small Levenberg-Marquardt for a few parameters with central-difference Jacobians.
#include "tofnav/correction/levenberg_marquardt.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace tofnav {
namespace {

struct Evaluator {
  const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& residuals;
  int count = 0;
  Eigen::VectorXd operator()(const Eigen::VectorXd& x) {
    ++count;
    return residuals(x);
  }
};

Eigen::MatrixXd Jacobian(Evaluator& eval, const Eigen::VectorXd& x, const Eigen::VectorXd& steps,
                         Eigen::Index rows) {
  Eigen::MatrixXd j(rows, x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    Eigen::VectorXd plus = x, minus = x;
    plus(i) += steps(i);
    minus(i) -= steps(i);
    j.col(i) = (eval(plus) - eval(minus)) / (2.0 * steps(i));
  }
  return j;
}

}  // namespace

void LevenbergMarquardtOptions::Check() const {
  if (max_iterations < 1 || !(initial_damping > 0.0) || !(relative_cost_tolerance >= 0.0) ||
      !(relative_step_tolerance >= 0.0)) {
    throw std::invalid_argument(
        "LevenbergMarquardtOptions: need max_iterations >= 1, initial_damping > 0 and "
        "non-negative tolerances");
  }
}

LevenbergMarquardtResult MinimiseLeastSquares(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& residuals,
    const Eigen::VectorXd& start, const Eigen::VectorXd& difference_steps,
    const LevenbergMarquardtOptions& options) {
  options.Check();
  if (start.size() == 0 || difference_steps.size() != start.size() ||
      !(difference_steps.array() > 0.0).all()) {
    throw std::invalid_argument("MinimiseLeastSquares: one positive difference step per parameter");
  }
  Evaluator eval{residuals};
  LevenbergMarquardtResult out;
  Eigen::VectorXd x = start;
  Eigen::VectorXd r = eval(x);
  double cost = 0.5 * r.squaredNorm();
  out.initial_cost = cost;
  double lambda = options.initial_damping;
  Eigen::MatrixXd j = Jacobian(eval, x, difference_steps, r.size());
  for (int it = 0; it < options.max_iterations; ++it) {
    out.iterations = it + 1;
    const Eigen::MatrixXd jtj = j.transpose() * j;
    const Eigen::VectorXd g = j.transpose() * r;
    bool improved = false;
    bool small_step = false;
    for (int attempt = 0; attempt < 12 && !improved; ++attempt) {
      Eigen::MatrixXd a = jtj;
      a.diagonal() += lambda * jtj.diagonal().cwiseMax(1e-12);
      const Eigen::VectorXd step = a.ldlt().solve(-g);
      const Eigen::VectorXd candidate = x + step;
      const Eigen::VectorXd rc = eval(candidate);
      const double cost_c = 0.5 * rc.squaredNorm();
      small_step =
          (step.array().abs() < options.relative_step_tolerance * difference_steps.array()).all();
      if (std::isfinite(cost_c) && cost_c < cost) {
        const double decrease = (cost - cost_c) / std::max(cost, 1e-300);
        x = candidate, r = rc, cost = cost_c;
        lambda = std::max(lambda / 3.0, 1e-9);
        improved = true;
        if (decrease < options.relative_cost_tolerance) small_step = true;
      } else {
        lambda *= 4.0;
      }
      if (small_step) break;
    }
    if (!improved || small_step) break;
    j = Jacobian(eval, x, difference_steps, r.size());
  }
  out.parameters = x;
  out.final_cost = cost;
  out.information = j.transpose() * j;
  out.standard_errors =
      Eigen::VectorXd::Constant(x.size(), std::numeric_limits<double>::quiet_NaN());
  const Eigen::Index dof = r.size() - x.size();
  if (dof > 0 && out.information.fullPivLu().isInvertible()) {
    const Eigen::MatrixXd cov = out.information.inverse() * (2.0 * cost / static_cast<double>(dof));
    out.standard_errors = cov.diagonal().cwiseMax(0.0).cwiseSqrt();
  }
  out.evaluations = eval.count;
  return out;
}

}  // namespace tofnav
