// SPDX-License-Identifier: BSD-3-Clause
// Two-model (still / turning) orientation filter in `world` (docs/tracking.md 1).
#include "tofnav/tracking/world_orientation_filter.hpp"

#include <algorithm>
#include <cmath>

#include "tofnav/core/require.hpp"
#include "tofnav/core/rotation_vector.hpp"

namespace tofnav {

void WorldOrientationOptions::Check() const {
  Require(std::isfinite(rotation_sigma_rad) && rotation_sigma_rad > 0.0,
          "WorldOrientationOptions::rotation_sigma_rad must be > 0");
  Require(std::isfinite(turning_rate_sigma_rad_per_s) && turning_rate_sigma_rad_per_s > 0.0 &&
              std::isfinite(turning_accel_sigma_rad_per_s2) && turning_accel_sigma_rad_per_s2 > 0.0,
          "WorldOrientationOptions: the turning model's sigmas must be > 0");
  Require(std::isfinite(still_sigma_rad_per_s) && still_sigma_rad_per_s >= 0.0,
          "WorldOrientationOptions::still_sigma_rad_per_s must be >= 0");
  Require(std::isfinite(still_dwell_s) && still_dwell_s > 0.0 && std::isfinite(turning_dwell_s) &&
              turning_dwell_s > 0.0,
          "WorldOrientationOptions: the dwell times must be > 0");
  Require(gate_chi2 > 0.0 && gate_floor_rad >= 0.0 && boost_chi2 > 0.0,
          "WorldOrientationOptions: gate_chi2 and boost_chi2 must be > 0, gate_floor_rad >= 0");
  Require(max_gated >= 1, "WorldOrientationOptions::max_gated must be >= 1");
  Require(max_gap_s > 0.0, "WorldOrientationOptions::max_gap_s must be > 0");
}

WorldOrientationFilter::WorldOrientationFilter(const WorldOrientationOptions& options)
    : options_(options) {
  options.Check();
}

void WorldOrientationFilter::Initialise(const Eigen::Quaterniond& measured, double timestamp_s,
                                        double variance_scale) {
  initialised_ = true;
  last_s_ = timestamp_s;
  const double r = variance_scale * options_.rotation_sigma_rad * options_.rotation_sigma_rad;
  const double rates[2] = {options_.still_sigma_rad_per_s, options_.turning_rate_sigma_rad_per_s};
  for (int k = 0; k < 2; ++k) {
    model_[k] = {measured, Eigen::Vector3d::Zero(), {r, 0.0, rates[k] * rates[k]}};
  }
  // The chain's stationary share: still for still_dwell_s, turning for turning_dwell_s.
  const double still =
      models() == 2 ? options_.still_dwell_s / (options_.still_dwell_s + options_.turning_dwell_s)
                    : 0.0;
  probability_ = {still, 1.0 - still};
  gated_in_a_row_ = 0;
  init_variance_scale_ = variance_scale;
  only_initialised_ = true;
}

// The weighted mean of the models' orientations, taken in the tangent space of the heaviest.
Eigen::Quaterniond WorldOrientationFilter::Combined(const std::array<Model, 2>& models,
                                                    const std::array<double, 2>& weights) const {
  const int heaviest = weights[kStill] > weights[kTurning] ? kStill : kTurning;
  const Eigen::Quaterniond& base = models[heaviest].rotation;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int k = 0; k < 2; ++k) {
    if (weights[k] > 0.0) mean += weights[k] * RotationVector(models[k].rotation * base.inverse());
  }
  return (FromRotationVector(mean) * base).normalized();
}

double WorldOrientationFilter::CombinedVariance(const std::array<Model, 2>& models,
                                                const std::array<double, 2>& weights,
                                                const Eigen::Quaterniond& combined) {
  double variance = 0.0;  // each model's own, and the spread of their means (isotropic)
  for (int k = 0; k < 2; ++k) {
    if (weights[k] <= 0.0) continue;
    const Eigen::Vector3d offset = RotationVector(models[k].rotation * combined.inverse());
    variance += weights[k] * (models[k].cov.pp + offset.squaredNorm() / 3.0);
  }
  return variance;
}

WorldOrientationUpdate WorldOrientationFilter::Update(const Eigen::Quaterniond& measured,
                                                      double timestamp_s, double variance_scale) {
  Require(std::isfinite(variance_scale) && variance_scale >= 1.0,
          "WorldOrientationFilter::Update: variance_scale must be >= 1");
  const double dt = timestamp_s - last_s_;
  if (!initialised_ || dt < 0.0 || dt > options_.max_gap_s) {
    Initialise(measured, timestamp_s, variance_scale);
    return {measured, false, true, probability_[kStill]};
  }
  const int first = models() == 2 ? kStill : kTurning;
  // Mixing (IMM step 1): p[i][j] = P(model j now | model i before) over dt.
  const double leave_still = -std::expm1(-dt / options_.still_dwell_s);
  const double leave_turning = -std::expm1(-dt / options_.turning_dwell_s);
  const double p[2][2] = {{1.0 - leave_still, leave_still}, {leave_turning, 1.0 - leave_turning}};
  std::array<double, 2> predicted_probability{0.0, 1.0};  // the turning model alone
  std::array<Model, 2> mixed = model_;
  for (int j = 0; j < 2 && first == kStill; ++j) {
    predicted_probability[j] =
        p[kStill][j] * probability_[kStill] + p[kTurning][j] * probability_[kTurning];
    const Eigen::Quaterniond& base = model_[j].rotation;
    std::array<double, 2> w{};
    std::array<Eigen::Vector3d, 2> offset;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero(), rate = Eigen::Vector3d::Zero();
    for (int i = 0; i < 2; ++i) {
      w[i] = p[i][j] * probability_[i] / predicted_probability[j];
      offset[i] = RotationVector(model_[i].rotation * base.inverse());
      mean += w[i] * offset[i];
      rate += w[i] * model_[i].rate_rad_per_s;
    }
    RateCovariance cov;
    for (int i = 0; i < 2; ++i) {  // the spread of the means counts, per axis (isotropic)
      const Eigen::Vector3d d = offset[i] - mean, v = model_[i].rate_rad_per_s - rate;
      cov.pp += w[i] * (model_[i].cov.pp + d.squaredNorm() / 3.0);
      cov.pv += w[i] * (model_[i].cov.pv + d.dot(v) / 3.0);
      cov.vv += w[i] * (model_[i].cov.vv + v.squaredNorm() / 3.0);
    }
    mixed[j] = {(FromRotationVector(mean) * base).normalized(), rate, cov};
  }
  // Prediction and innovation per model.
  const double r = variance_scale * options_.rotation_sigma_rad * options_.rotation_sigma_rad;
  const double accel[2] = {options_.still_sigma_rad_per_s, options_.turning_accel_sigma_rad_per_s2};
  std::array<Model, 2> predicted = mixed;
  std::array<Eigen::Vector3d, 2> innovation;
  std::array<double, 2> log_likelihood{0.0, 0.0};
  for (int k = first; k < 2; ++k) {
    predicted[k].rotation = FromRotationVector(mixed[k].rate_rad_per_s * dt) * mixed[k].rotation;
    predicted[k].cov = PropagateConstantVelocity(mixed[k].cov, dt, accel[k]);
    innovation[k] = RotationVector(measured * predicted[k].rotation.inverse());
    const double s = predicted[k].cov.pp + r;
    log_likelihood[k] = -0.5 * innovation[k].squaredNorm() / s - 1.5 * std::log(s);
  }
  // The gate judges the turning model, the one that allows the most motion.
  const double s_turning = predicted[kTurning].cov.pp + r;
  const double chi2 = innovation[kTurning].squaredNorm() / s_turning;
  if (chi2 > options_.gate_chi2 && innovation[kTurning].norm() > options_.gate_floor_rad) {
    // A state started from one measurement that fitted worse than this one does not lock the
    // better one out: start again from it.
    const bool poor_start = only_initialised_ && variance_scale < init_variance_scale_;
    if (!poor_start && ++gated_in_a_row_ < options_.max_gated) {
      const Eigen::Quaterniond held = Combined(predicted, predicted_probability);
      return {held, true, false, probability_[kStill],
              CombinedVariance(predicted, predicted_probability, held) / r};
    }
    Initialise(measured, timestamp_s, variance_scale);  // a real turn or move
    return {measured, false, true, probability_[kStill]};
  }
  gated_in_a_row_ = 0;
  only_initialised_ = false;
  const double best = first == kStill ? std::max(log_likelihood[kStill], log_likelihood[kTurning])
                                      : log_likelihood[kTurning];
  double total = 0.0;
  for (int k = first; k < 2; ++k) {
    const RateCovarianceUpdate u = MeasureValue(predicted[k].cov, r);
    model_[k].rotation =
        (FromRotationVector(u.value_gain * innovation[k]) * predicted[k].rotation).normalized();
    model_[k].rate_rad_per_s = mixed[k].rate_rad_per_s + u.rate_gain * innovation[k];
    model_[k].cov = u.posterior;
    probability_[k] = predicted_probability[k] * std::exp(log_likelihood[k] - best);
    total += probability_[k];
  }
  for (int k = first; k < 2; ++k) probability_[k] /= total;
  if (chi2 > options_.boost_chi2) {  // a turn starts: the turning model's rate opens up
    model_[kTurning].cov.vv +=
        options_.turning_rate_sigma_rad_per_s * options_.turning_rate_sigma_rad_per_s;
  }
  last_s_ = timestamp_s;
  const Eigen::Quaterniond filtered = Combined(model_, probability_);
  return {filtered, false, false, probability_[kStill],
          CombinedVariance(model_, probability_, filtered) / r};
}

}  // namespace tofnav
