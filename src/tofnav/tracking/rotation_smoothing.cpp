// SPDX-License-Identifier: BSD-3-Clause
// Local linear fit of rotations over time in the tangent space at each sample.
#include "tofnav/tracking/rotation_smoothing.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "tofnav/core/require.hpp"
#include "tofnav/core/rotation_vector.hpp"

namespace tofnav {
namespace {

// v(dt) = at_t + rate dt, least squares over the kept samples of a window.
struct Line {
  Eigen::Vector3d at_t, rate;
};

std::optional<Line> FitLine(const std::vector<std::size_t>& window,
                            const std::vector<Eigen::Vector3d>& v, const std::vector<bool>& kept,
                            std::span<const double> time_s, double t, std::size_t min_samples) {
  double s0 = 0.0, s1 = 0.0, s2 = 0.0;
  Eigen::Vector3d sv = Eigen::Vector3d::Zero(), svt = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < window.size(); ++k) {
    if (!kept[k]) continue;
    const double dt = time_s[window[k]] - t;
    s0 += 1.0, s1 += dt, s2 += dt * dt;
    sv += v[k], svt += v[k] * dt;
  }
  if (s0 < static_cast<double>(min_samples)) return std::nullopt;
  const double det = s0 * s2 - s1 * s1;
  // Samples that share one time (or one sample) have no slope: their mean.
  if (det <= 1e-12 * s0 * s0) return Line{sv / s0, Eigen::Vector3d::Zero()};
  return Line{(s2 * sv - s1 * svt) / det, (s0 * svt - s1 * sv) / det};
}

}  // namespace

void RotationSmoothingOptions::Check() const {
  Require(std::isfinite(half_window_s) && half_window_s >= 0.0,
          "RotationSmoothingOptions::half_window_s must be >= 0");
  Require(min_samples >= 1, "RotationSmoothingOptions::min_samples must be >= 1");
  Require(std::isfinite(max_deviation_rad) && max_deviation_rad > 0.0,
          "RotationSmoothingOptions::max_deviation_rad must be > 0");
}

std::vector<std::optional<Eigen::Quaterniond>> SmoothWorldRotations(
    std::span<const std::optional<Rigid3d>> world_from_tool, std::span<const double> time_s,
    const RotationSmoothingOptions& options) {
  options.Check();
  Require(world_from_tool.size() == time_s.size(),
          "SmoothWorldRotations: one time per pose is required");
  const std::size_t n = world_from_tool.size();
  std::vector<std::optional<Eigen::Quaterniond>> out(n);
  // The posed samples in time order (a recording's frames may come out of order).
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < n; ++i) {
    Require(std::isfinite(time_s[i]), "SmoothWorldRotations: times must be finite");
    if (world_from_tool[i]) order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return time_s[a] < time_s[b]; });
  std::size_t lo = 0;  // the window's first position in `order`
  std::vector<std::size_t> window;
  std::vector<Eigen::Vector3d> v;
  std::vector<bool> kept;
  for (std::size_t p = 0; p < order.size(); ++p) {
    const std::size_t i = order[p];
    const double t = time_s[i];
    while (time_s[order[lo]] < t - options.half_window_s) ++lo;
    const Eigen::Quaterniond& own = world_from_tool[i]->rotation;
    const Eigen::Quaterniond own_inverse = own.conjugate();
    window.clear(), v.clear();
    for (std::size_t q = lo; q < order.size() && time_s[order[q]] <= t + options.half_window_s;
         ++q) {
      window.push_back(order[q]);
      v.push_back(RotationVector(world_from_tool[order[q]]->rotation * own_inverse));
    }
    kept.assign(window.size(), true);
    // Straight-line fit, then again without the samples farther than max_deviation_rad from the
    // first line (a jump among the neighbours would otherwise tilt them all).
    std::optional<Line> line = FitLine(window, v, kept, time_s, t, options.min_samples);
    if (!line) continue;
    for (std::size_t k = 0; k < window.size(); ++k) {
      const double dt = time_s[window[k]] - t;
      kept[k] = (v[k] - line->at_t - line->rate * dt).norm() <= options.max_deviation_rad;
    }
    line = FitLine(window, v, kept, time_s, t, options.min_samples);
    if (!line || line->at_t.norm() > options.max_deviation_rad) continue;  // or itself a jump
    out[i] = (FromRotationVector(line->at_t) * own).normalized();
  }
  return out;
}

std::size_t SmoothAhatRotations(std::span<std::optional<Rigid3d>> ahat_from_tool,
                                std::span<const std::optional<Rigid3d>> world_from_ahat,
                                std::span<const double> time_s,
                                const RotationSmoothingOptions& options) {
  Require(ahat_from_tool.size() == world_from_ahat.size(),
          "SmoothAhatRotations: one world_from_ahat per pose is required");
  std::vector<std::optional<Rigid3d>> world_from_tool(ahat_from_tool.size());
  for (std::size_t i = 0; i < ahat_from_tool.size(); ++i) {
    if (ahat_from_tool[i] && world_from_ahat[i]) {
      world_from_tool[i] = *world_from_ahat[i] * *ahat_from_tool[i];
    }
  }
  const std::vector<std::optional<Eigen::Quaterniond>> smoothed =
      SmoothWorldRotations(world_from_tool, time_s, options);
  std::size_t count = 0;
  for (std::size_t i = 0; i < smoothed.size(); ++i) {
    if (!smoothed[i]) continue;
    ahat_from_tool[i]->rotation =
        (world_from_ahat[i]->rotation.conjugate() * *smoothed[i]).normalized();
    ++count;
  }
  return count;
}

}  // namespace tofnav
