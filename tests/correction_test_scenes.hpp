// SPDX-License-Identifier: BSD-3-Clause
// Synthetic AHAT frames with analytic truth for the correction tests: planes, stickers, bias.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>

#include "tofnav/core/image.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav::testing {

inline const AhatCamera& CorrectionCamera() {
  static const AhatCamera camera(MakeSyntheticAhatCalibration());
  return camera;
}

/// A plane n . X = offset (unit n pointing away from the camera side, offset > 0).
struct TestPlane {
  Eigen::Vector3d normal;
  double offset_mm = 0.0;
  /// True range along `ray`, 0 when the plane is behind the camera or grazing.
  double Range(const Eigen::Vector3d& ray) const {
    const double c = normal.dot(ray);
    return c > 1e-3 ? offset_mm / c : 0.0;
  }
  double Incidence(const Eigen::Vector3d& ray) const {
    return std::acos(std::abs(normal.dot(ray)));
  }
};

/// A plane through `point` facing the camera, turned by `angle_rad` about the y axis.
inline TestPlane TiltedPlane(double distance_mm, double angle_rad) {
  const Eigen::Vector3d n(std::sin(angle_rad), 0.0, std::cos(angle_rad));
  return {n, distance_mm * n.z()};
}

/// Frame of true range `truth(u, v, ray)` [mm] with a measured range `measured(d, ray)` rounded to
/// mm, uniform AB `ab`, inside the pixel window [min_px, max_px]^2; pixels with truth 0 and those
/// outside the window are invalid (a small window keeps unoptimised tests fast).
inline AhatFrame SyntheticFrame(
    const std::function<double(int, int, const Eigen::Vector3d&)>& truth,
    const std::function<double(double, int, int)>& measured, std::uint16_t ab,
    Image<float>* truth_out = nullptr, int min_px = 0, int max_px = 511) {
  const AhatCamera& camera = CorrectionCamera();
  AhatFrame frame;
  frame.range_mm = Image<std::uint16_t>(camera.width(), camera.height());
  frame.ab = Image<std::uint16_t>(camera.width(), camera.height(), ab);
  if (truth_out) *truth_out = Image<float>(camera.width(), camera.height());
  for (int v = std::max(min_px, 0); v <= std::min(max_px, camera.height() - 1); ++v) {
    for (int u = std::max(min_px, 0); u <= std::min(max_px, camera.width() - 1); ++u) {
      if (!camera.IsValid(u, v)) continue;
      const Eigen::Vector3d ray = camera.PixelRay(u, v).cast<double>();
      const double d = truth(u, v, ray);
      if (d <= 0.0) continue;
      if (truth_out) (*truth_out)(u, v) = static_cast<float>(d);
      frame.range_mm(u, v) = static_cast<std::uint16_t>(std::lround(measured(d, u, v)));
    }
  }
  return frame;
}

}  // namespace tofnav::testing
