// SPDX-License-Identifier: BSD-3-Clause
// Test-only scenes for markers/, tracking/ and correction/: camera, tools, small render windows.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sim/render.hpp"
#include "tofnav/sim/shapes.hpp"

namespace tofnav::testing {

/// The synthetic equidistant AHAT camera (f = 254 px), built once per test binary.
inline const AhatCamera& TestCamera() {
  static const AhatCamera camera(MakeSyntheticAhatCalibration());
  return camera;
}

/// Two 4-sphere tools with distinct edges: within a tool they differ by >= 7 mm, between the
/// tools by >= 5 mm; both non-coplanar (z spread 20-25 mm). Tool frame: +z towards the camera.
inline Points3d ReferenceToolMarkers() {
  return {{-20, -45, 35}, {0, 50, 30}, {60, -55, 15}, {-30, 10, 15}};
}
inline Points3d SecondToolMarkers() {
  return {{5, -55, 10}, {15, 35, 5}, {-40, 5, 30}, {55, 50, 20}};
}

/// Pose of a tool whose +z faces the camera, centred at `position_in_ahat`, turned by `tilt_rad`
/// about the tool x axis and `spin_rad` about its z axis.
inline Rigid3d FacingToolPose(const Eigen::Vector3d& position_in_ahat, double tilt_rad = 0.0,
                              double spin_rad = 0.0) {
  const Eigen::Quaterniond flip(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond spin(Eigen::AngleAxisd(spin_rad, Eigen::Vector3d::UnitZ()));
  return Rigid3d(flip * tilt * spin, position_in_ahat);
}

/// A scene with a diffuse wall `wall_behind_mm` behind z = wall_z_mm and no tools yet; returns
/// the retro-reflective material index through `retro`.
/// `retro_angle_gain_mm_per_rad`: the sheeting's entrance-angle term (unset: the preset's).
inline sim::Scene WallScene(double wall_z_mm, int& retro,
                            sim::RetroCurve curve = sim::RetroCurve::kLinear,
                            std::optional<double> retro_angle_gain_mm_per_rad = std::nullopt) {
  sim::Scene scene;
  const int wall = scene.AddMaterial(sim::DiffuseMaterial(0.5));
  sim::Material tape = sim::RetroReflectiveMaterial(curve);
  if (retro_angle_gain_mm_per_rad) tape.retro_angle_gain_mm_per_rad = *retro_angle_gain_mm_per_rad;
  retro = scene.AddMaterial(tape);
  const Eigen::Quaterniond flip(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()));
  scene.AddObject("wall", sim::PlaneMesh(6000.0, 6000.0), wall,
                  Rigid3d(flip, Eigen::Vector3d(0.0, 0.0, wall_z_mm)));
  return scene;
}

inline sim::Tool SphereTool(const std::string& name, const Points3d& markers_in_tool,
                            double diameter_mm, int material, const Rigid3d& scene_from_tool) {
  sim::Tool tool{name, {}, scene_from_tool};
  for (const Eigen::Vector3d& p : markers_in_tool) {
    tool.markers.push_back(sim::SphereMarker(p, diameter_mm, material));
  }
  return tool;
}

/// Smallest pixel window holding every marker of the scene's tools with `margin_px` around its
/// projected centre (plus the marker's projected radius); scene frame = ahat.
inline sim::PixelRect MarkerWindow(const sim::Scene& scene, int margin_px = 6) {
  double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
  for (const sim::Tool& tool : scene.tools) {
    for (const sim::Marker& m : tool.markers) {
      const Eigen::Vector3d c = tool.scene_from_tool * m.centre_in_tool;
      const auto pixel = TestCamera().Project(c);
      if (!pixel) continue;
      const double radius_px = 260.0 * 0.5 * m.diameter_mm / c.norm() + margin_px;
      u0 = std::min(u0, pixel->x() - radius_px);
      v0 = std::min(v0, pixel->y() - radius_px);
      u1 = std::max(u1, pixel->x() + radius_px);
      v1 = std::max(v1, pixel->y() + radius_px);
    }
  }
  const int iu0 = std::clamp(static_cast<int>(std::floor(u0)), 0, kAhatWidth - 1);
  const int iv0 = std::clamp(static_cast<int>(std::floor(v0)), 0, kAhatHeight - 1);
  const int iu1 = std::clamp(static_cast<int>(std::ceil(u1)), iu0 + 1, kAhatWidth);
  const int iv1 = std::clamp(static_cast<int>(std::ceil(v1)), iv0 + 1, kAhatHeight);
  return {iu0, iv0, iu1 - iu0, iv1 - iv0};
}

/// Realistic render (noise, physical bias, scatter) of the marker window only.
inline sim::RenderResult RenderMarkers(const sim::Scene& scene, std::uint64_t seed,
                                       sim::RenderOptions options = {}) {
  options.window = MarkerWindow(scene);
  std::mt19937_64 rng(seed);
  return sim::RenderAhatFrame(scene, TestCamera(), Rigid3d::Identity(), options, rng);
}

}  // namespace tofnav::testing
