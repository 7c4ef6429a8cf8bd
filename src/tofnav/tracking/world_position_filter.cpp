// SPDX-License-Identifier: BSD-3-Clause
// WorldPositionFilter: a world-fixed point's position fused with each frame's measurement.
#include "tofnav/tracking/world_position_filter.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// The measurement's noise in `ahat`: along_sigma^2 along the unit ray, across_sigma^2 across it.
Eigen::Matrix3d MeasurementNoise(const Eigen::Vector3d& point_in_ahat,
                                 const WorldPositionOptions& o) {
  const double range_mm = point_in_ahat.norm();
  const double relative = std::max(range_mm, 1.0) / o.noise_range_mm;
  const double along = o.along_ray_sigma_mm * std::pow(relative, o.along_ray_exponent);
  const double across = o.across_ray_sigma_mm * std::pow(relative, o.across_ray_exponent);
  const Eigen::Vector3d u = point_in_ahat / std::max(range_mm, 1e-9);
  return across * across * Eigen::Matrix3d::Identity() +
         (along * along - across * across) * u * u.transpose();
}

// The shared rig error's posterior (mean, covariance) from the points in `use`: its prior is
// rig_variance_mm2 per axis, each point's innovation is it plus noise of the point's held and
// estimate covariances.
std::pair<Eigen::Vector3d, Eigen::Matrix3d> SharedError(std::span<const WorldPointTerms> points,
                                                        const std::vector<bool>& use,
                                                        double rig_variance_mm2) {
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity() / rig_variance_mm2;
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!use[i]) continue;
    const WorldPointTerms& p = points[i];
    const Eigen::Matrix3d s_inv = (p.held_cov_mm2 + p.estimate_cov_mm2).inverse();
    information += s_inv;
    weighted += s_inv * (p.estimate_in_ahat - p.predicted_in_ahat);
  }
  const Eigen::Matrix3d cov = information.inverse();
  return {cov * weighted, cov};
}

}  // namespace

std::vector<Eigen::Vector3d> FuseWithSharedRigError(std::span<const WorldPointTerms> points,
                                                    double rig_variance_mm2, double gate_chi2,
                                                    std::vector<bool>* joined) {
  Require(rig_variance_mm2 > 0.0 && gate_chi2 > 0.0,
          "FuseWithSharedRigError: the rig variance and the gate must be > 0");
  const std::size_t n = points.size();
  // Each point against the shared error the others give; the worst disagreeing one leaves, and
  // the rest are checked again (one moved tool must not drag the others out with it).
  std::vector<bool> use(n, true);
  for (std::size_t left = n; left > 1; --left) {
    double worst_chi2 = gate_chi2;
    std::optional<std::size_t> worst;
    for (std::size_t i = 0; i < n; ++i) {
      if (!use[i]) continue;
      std::vector<bool> others = use;
      others[i] = false;
      const auto [error, cov] = SharedError(points, others, rig_variance_mm2);
      const WorldPointTerms& p = points[i];
      const Eigen::Vector3d d = p.estimate_in_ahat - p.predicted_in_ahat - error;
      const Eigen::Matrix3d s = p.held_cov_mm2 + p.estimate_cov_mm2 + cov;
      const double chi2 = d.dot(s.ldlt().solve(d));
      if (chi2 > worst_chi2) {
        worst_chi2 = chi2;
        worst = i;
      }
    }
    if (!worst) break;
    use[*worst] = false;
  }
  if (std::count(use.begin(), use.end(), true) < 2) use.assign(n, false);
  // The joined points' shared error, once; a point fused alone takes it from its own innovation.
  const Eigen::Vector3d joint_error = SharedError(points, use, rig_variance_mm2).first;
  std::vector<Eigen::Vector3d> fused(n);
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector3d error = joint_error;
    if (!use[i]) {
      std::vector<bool> alone(n, false);
      alone[i] = true;
      error = SharedError(points, alone, rig_variance_mm2).first;
    }
    // The point is the prediction plus the shared error plus the held position's own error,
    // which the innovation left after the shared error tells (Gaussian conditioning).
    const WorldPointTerms& p = points[i];
    const Eigen::Matrix3d s = p.held_cov_mm2 + p.estimate_cov_mm2;
    const Eigen::Vector3d rest = p.estimate_in_ahat - p.predicted_in_ahat - error;
    fused[i] = p.predicted_in_ahat + error + p.held_cov_mm2 * s.ldlt().solve(rest);
  }
  if (joined) *joined = use;
  return fused;
}

void WorldPositionOptions::Check() const {
  Require(along_ray_sigma_mm > 0.0 && across_ray_sigma_mm > 0.0 && noise_range_mm > 0.0 &&
              std::isfinite(along_ray_exponent) && std::isfinite(across_ray_exponent),
          "WorldPositionOptions: the noise sigmas and noise_range_mm must be > 0");
  Require(accel_sigma_mm_per_s2 > 0.0 && initial_speed_sigma_mm_per_s > 0.0 && max_gap_s > 0.0,
          "WorldPositionOptions: accel_sigma_mm_per_s2, initial_speed_sigma_mm_per_s and "
          "max_gap_s must be > 0");
  Require(gate_chi2 > 0.0 && max_gated >= 1,
          "WorldPositionOptions: gate_chi2 must be > 0 and max_gated >= 1");
  Require(initial_jitter_sigma_mm >= min_jitter_sigma_mm && min_jitter_sigma_mm > 0.0 &&
              jitter_window >= 1,
          "WorldPositionOptions: initial_jitter_sigma_mm >= min_jitter_sigma_mm > 0 and "
          "jitter_window >= 1");
}

RigJitterEstimate::RigJitterEstimate(const WorldPositionOptions& options) : options_(options) {
  options.Check();
  Reset();
}

void RigJitterEstimate::Add(double sample_mm2) {
  count_ = std::min(count_ + 1, options_.jitter_window);
  const double floor_mm2 = options_.min_jitter_sigma_mm * options_.min_jitter_sigma_mm;
  variance_mm2_ += (std::max(sample_mm2, floor_mm2) - variance_mm2_) / (count_ + 1);
  variance_mm2_ = std::max(variance_mm2_, floor_mm2);
}

void RigJitterEstimate::Reset() {
  variance_mm2_ = options_.initial_jitter_sigma_mm * options_.initial_jitter_sigma_mm;
  count_ = 0;
}

WorldPositionFilter::WorldPositionFilter(const WorldPositionOptions& options) : options_(options) {
  options.Check();
}

void WorldPositionFilter::Reset() {
  initialised_ = false;
  gated_in_a_row_ = 0;
}

void WorldPositionFilter::Initialise(const Eigen::Vector3d& measured_in_world,
                                     const Eigen::Matrix3d& noise_in_world, double timestamp_s) {
  state_.head<3>() = measured_in_world;
  state_.tail<3>().setZero();
  cov_.setZero();
  cov_.topLeftCorner<3, 3>() = noise_in_world;
  const double v = options_.initial_speed_sigma_mm_per_s;
  cov_.bottomRightCorner<3, 3>() = v * v * Eigen::Matrix3d::Identity();
  last_s_ = timestamp_s;
  initialised_ = true;
  gated_in_a_row_ = 0;
}

WorldPositionUpdate WorldPositionFilter::Update(const WorldPositionInput& input,
                                                const Rigid3d& world_from_ahat, double timestamp_s,
                                                RigJitterEstimate& jitter) {
  Require(
      std::isfinite(input.variance_scale) && std::isfinite(input.estimate_variance_ratio) &&
          input.estimate_variance_ratio > 0.0,
      "WorldPositionFilter::Update: the variance scale and ratio must be finite, the ratio > 0");
  const Eigen::Vector3d& measured_in_ahat = input.measured_in_ahat;
  const Eigen::Matrix3d rotation = world_from_ahat.rotation.toRotationMatrix();
  const Eigen::Matrix3d measurement =
      std::max(1.0, input.variance_scale) * MeasurementNoise(measured_in_ahat, options_);
  const Eigen::Matrix3d jitter_cov = jitter.variance_mm2() * Eigen::Matrix3d::Identity();
  const Eigen::Vector3d measured_in_world = world_from_ahat * measured_in_ahat;
  WorldPositionUpdate out;
  const double dt = timestamp_s - last_s_;
  if (!initialised_ || dt < 0.0 || dt > options_.max_gap_s) {
    Initialise(measured_in_world, rotation * (measurement + jitter_cov) * rotation.transpose(),
               timestamp_s);
    out.reset = true;
    return out;
  }
  // Predict: constant velocity, white acceleration (per axis, the same 2 x 2 block).
  Matrix6d f = Matrix6d::Identity();
  f.topRightCorner<3, 3>() = dt * Eigen::Matrix3d::Identity();
  const double q = options_.accel_sigma_mm_per_s2 * options_.accel_sigma_mm_per_s2;
  Matrix6d noise = Matrix6d::Zero();
  noise.topLeftCorner<3, 3>() = q * dt * dt * dt / 3.0 * Eigen::Matrix3d::Identity();
  noise.topRightCorner<3, 3>() = q * dt * dt / 2.0 * Eigen::Matrix3d::Identity();
  noise.bottomLeftCorner<3, 3>() = noise.topRightCorner<3, 3>();
  noise.bottomRightCorner<3, 3>() = q * dt * Eigen::Matrix3d::Identity();
  const Eigen::Matrix<double, 6, 1> state = f * state_;
  const Matrix6d cov = f * cov_ * f.transpose() + noise;
  // The prediction in `ahat` through this frame's rig pose, and the innovation.
  const Eigen::Vector3d predicted = world_from_ahat.Inverse() * Eigen::Vector3d(state.head<3>());
  const Eigen::Matrix3d held = rotation.transpose() * cov.topLeftCorner<3, 3>() * rotation;
  const Eigen::Vector3d innovation = measured_in_ahat - predicted;
  const Eigen::Matrix3d innovation_cov = measurement + held + jitter_cov;
  const Eigen::LDLT<Eigen::Matrix3d> solver(innovation_cov);
  const double chi2 = innovation.dot(solver.solve(innovation));
  // Across the ray the measurement is precise: what is left of the innovation there, beyond
  // the measurement's and the held position's variance, is the rig pose's error (two axes).
  const Eigen::Vector3d u = measured_in_ahat.normalized();
  const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - u * u.transpose();
  if (chi2 <= 4.0 * options_.gate_chi2) {  // an outlier says nothing about the jitter
    const double known = (across * (measurement + held) * across).trace();
    jitter.Add(0.5 * ((across * innovation).squaredNorm() - known));
  }
  if (chi2 > options_.gate_chi2) {
    out.gated = true;
    if (++gated_in_a_row_ >= options_.max_gated) {
      Initialise(measured_in_world, rotation * (measurement + jitter_cov) * rotation.transpose(),
                 timestamp_s);
      out.reset = true;
    }
    return out;
  }
  gated_in_a_row_ = 0;
  out.terms = WorldPointTerms{.predicted_in_ahat = predicted,
                              .held_cov_mm2 = held,
                              .estimate_in_ahat = input.estimate_in_ahat,
                              .estimate_cov_mm2 = input.estimate_variance_ratio * measurement};
  out.fused_in_ahat =
      FuseWithSharedRigError(std::span(&*out.terms, 1), jitter.variance_mm2(), options_.gate_chi2)
          .front();
  // Update the world state with the measurement mapped by the rig pose (its jitter included):
  // the innovation covariance in `world` is R S R^T, so its inverse is R S^-1 R^T.
  const Eigen::Matrix<double, 6, 3> gain =
      cov.leftCols<3>() * rotation * solver.solve(rotation.transpose());
  state_ = state + gain * (measured_in_world - state.head<3>());
  cov_ = cov - gain * cov.topRows<3>();
  cov_ = 0.5 * (cov_ + cov_.transpose()).eval();
  last_s_ = timestamp_s;
  return out;
}

}  // namespace tofnav
