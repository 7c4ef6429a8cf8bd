// SPDX-License-Identifier: BSD-3-Clause
// The orientation of a tool that stands still in `world` most of the time and sometimes turns
// with the patient: two constant-velocity models, still and turning, mixed by how well each
// predicts (an interacting multiple model filter; docs/tracking.md 1, "The orientation held in
// the world").
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <optional>

#include "tofnav/tracking/constant_velocity.hpp"

namespace tofnav {

struct WorldOrientationOptions {
  /// One raw pose's orientation noise, per axis, before the caller's per-step scale.
  double rotation_sigma_rad = 0.003;
  /// The turning model: its rate at a (re-)start and its largest boost by a large innovation,
  /// and the white angular acceleration its rate wanders with.
  double turning_rate_sigma_rad_per_s = 0.003;
  double turning_accel_sigma_rad_per_s2 = 0.003;
  /// The still model: the same two figures; 0 leaves it out (the turning model alone).
  double still_sigma_rad_per_s = 0.0003;
  /// How long the tool stays still, and how long a turn lasts, on average: the Markov chain
  /// between the models (P(leave) = 1 - exp(-dt / dwell) per step).
  double still_dwell_s = 60.0;
  double turning_dwell_s = 2.0;
  /// The gate, judged on the turning model's prediction: chi-square of the orientation's
  /// innovation and an angle floor below which nothing is gated; after max_gated in a row the
  /// filter restarts (a real turn or a move of the patient).
  double gate_chi2 = 22.46;
  double gate_floor_rad = 0.035;
  double boost_chi2 = 16.27;
  int max_gated = 3;
  double max_gap_s = 5.0;  // no accepted measurement for longer: restart on the next
  void Check() const;      // throws std::invalid_argument naming the bad field
};

struct WorldOrientationUpdate {
  Eigen::Quaterniond filtered;  // the measurement on reset, the prediction when gated
  bool gated = false;
  bool reset = false;
  double still_probability = 0.0;  // the still model's weight after this step
  /// The filtered orientation's variance (per axis, the models' mixture) over this measurement's:
  /// 1 at a (re-)start, about 1/n after n still frames, what is left of one frame's noise.
  double variance_ratio = 1.0;
};

class WorldOrientationFilter {
 public:
  explicit WorldOrientationFilter(const WorldOrientationOptions& options = {});
  /// One measured world_from_tool orientation at `timestamp_s`; `variance_scale` >= 1 multiplies
  /// its noise variance (a poor fit, a far or partial pose).
  WorldOrientationUpdate Update(const Eigen::Quaterniond& measured, double timestamp_s,
                                double variance_scale = 1.0);
  void Reset() { initialised_ = false; }

 private:
  struct Model {
    Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
    Eigen::Vector3d rate_rad_per_s = Eigen::Vector3d::Zero();
    RateCovariance cov;
  };
  static constexpr int kStill = 0, kTurning = 1;
  int models() const { return options_.still_sigma_rad_per_s > 0.0 ? 2 : 1; }
  void Initialise(const Eigen::Quaterniond& measured, double timestamp_s, double variance_scale);
  Eigen::Quaterniond Combined(const std::array<Model, 2>& models,
                              const std::array<double, 2>& weights) const;
  /// The mixture's per-axis variance about `combined` [rad^2].
  static double CombinedVariance(const std::array<Model, 2>& models,
                                 const std::array<double, 2>& weights,
                                 const Eigen::Quaterniond& combined);

  WorldOrientationOptions options_;
  bool initialised_ = false;
  double last_s_ = 0.0;
  std::array<Model, 2> model_;  // [kStill], [kTurning]; the turning one alone when models() == 1
  std::array<double, 2> probability_{};
  int gated_in_a_row_ = 0;
  double init_variance_scale_ = 1.0;
  bool only_initialised_ = false;
};

}  // namespace tofnav
