// SPDX-License-Identifier: BSD-3-Clause
// Test-only helpers shared by the sim test files: the synthetic camera and simple scenes.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "tofnav/sensor/ahat_calibration.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sim/render.hpp"
#include "tofnav/sim/shapes.hpp"

namespace tofnav::sim::testing {

/// The synthetic equidistant AHAT camera (f = 254 px), built once per test binary.
inline const AhatCamera& TestCamera() {
  static const AhatCamera camera(MakeSyntheticAhatCalibration());
  return camera;
}

/// Pose of a board that faces the camera (normal -z in `ahat`) at depth z = distance_mm, tilted
/// by `tilt_rad` about the y axis through its centre.
inline Rigid3d FacingPose(double distance_mm, double tilt_rad = 0.0) {
  const Eigen::Quaterniond flip(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d::UnitY()));
  return Rigid3d(tilt * flip, Eigen::Vector3d(0.0, 0.0, distance_mm));
}

/// A single large board of `material` facing the camera.
inline Scene BoardScene(const Material& material, double distance_mm, double tilt_rad = 0.0) {
  Scene scene;
  const int m = scene.AddMaterial(material);
  scene.AddObject("board", PlaneMesh(4000.0, 4000.0), m, FacingPose(distance_mm, tilt_rad));
  return scene;
}

/// A square window of `size` px centred on pixel (u, v).
inline PixelRect WindowAround(int u, int v, int size) {
  return {u - size / 2, v - size / 2, size, size};
}

/// The pixel nearest the optical axis.
inline Eigen::Vector2i CentrePixel() {
  const Eigen::Vector2d p = *TestCamera().Project(Eigen::Vector3d::UnitZ());
  return {static_cast<int>(std::lround(p.x())), static_cast<int>(std::lround(p.y()))};
}

}  // namespace tofnav::sim::testing
