// SPDX-License-Identifier: BSD-3-Clause
// Test-only tools and synthetic detections for tracking/ tests (no rendering: fast).
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "marker_test_scenes.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/tracking/tool_geometry.hpp"

namespace tofnav::testing {

inline ToolGeometry ReferenceTool() {
  ToolGeometry tool;
  tool.name = "Reference";
  tool.markers_in_tool = ReferenceToolMarkers();
  return tool;
}

inline ToolGeometry SecondTool() {
  ToolGeometry tool;
  tool.name = "Pointer";
  tool.markers_in_tool = SecondToolMarkers();
  return tool;
}

/// Two flat plates of four Phi 10 mm discs, the second `offset_mm` along x and turned
/// `turn_deg` about y against the first, as one tool (a headframe's two reference plates).
inline ToolGeometry TwoPlateDiscTool(const std::vector<Eigen::Vector3d>& plate, double offset_mm,
                                     double turn_deg) {
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(turn_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  ToolGeometry tool;
  tool.name = "two_plates";
  tool.marker_type = MarkerType::kDisc;
  tool.marker_diameter_mm = 10.0;
  for (const Eigen::Vector3d& p : plate) tool.markers_in_tool.push_back(p);
  for (const Eigen::Vector3d& p : plate) {
    tool.markers_in_tool.push_back(Eigen::Vector3d(offset_mm, 0, 0) + turn * p);
  }
  return tool;
}

/// The paper's linear-stage structure (Sec. III-A.1): seven flat Phi 10 mm tape discs on a
/// board in the tool frame's z = 0 plane, facing +z; disc centres sit `height_mm` above it.
inline ToolGeometry StageStructure(double height_mm) {
  ToolGeometry s;
  s.name = "stage";
  s.marker_type = MarkerType::kDisc;
  s.marker_diameter_mm = 10.0;
  s.markers_in_tool = {{-60, -40, height_mm}, {5, -45, height_mm}, {55, -30, height_mm},
                       {-45, 40, height_mm},  {10, 30, height_mm}, {62, 45, height_mm},
                       {-5, -5, height_mm}};
  return s;
}

/// A detection whose MarkerCentre(radius) is exactly `centre` (no core samples).
inline DetectedMarker DetectionAt(const Eigen::Vector3d& centre_in_ahat, double radius_mm) {
  DetectedMarker m;
  m.ray_in_ahat = centre_in_ahat.normalized();
  m.surface_range_mm = centre_in_ahat.norm() - radius_mm;
  m.area_px = 30;
  m.ab_peak = 40000.0;
  return m;
}

/// Detections of `tool` at `ahat_from_tool` with isotropic centre noise [mm].
inline std::vector<DetectedMarker> ToolDetections(const ToolGeometry& tool,
                                                  const Rigid3d& ahat_from_tool, double noise_mm,
                                                  std::mt19937_64& rng) {
  std::normal_distribution<double> noise(0.0, noise_mm);
  std::vector<DetectedMarker> out;
  for (const Eigen::Vector3d& m : tool.markers_in_tool) {
    const Eigen::Vector3d c =
        ahat_from_tool * m + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    out.push_back(DetectionAt(c, tool.SurfaceToCentreMm()));
  }
  return out;
}

/// A ToF point's error at `point_in_ahat`: `along_mm` along its view ray, `across_mm` per axis
/// across it.
inline Eigen::Vector3d RayNoise(const Eigen::Vector3d& point_in_ahat, double along_mm,
                                double across_mm, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::Vector3d u = point_in_ahat.normalized();
  Eigen::Vector3d e(across_mm * normal(rng), across_mm * normal(rng), across_mm * normal(rng));
  return e + (along_mm * normal(rng) - e.dot(u)) * u;
}

/// Detections of `tool` at `ahat_from_tool` whose centres err as ToF markers do: `along_mm` along
/// the view ray (the range), `across_mm` per axis across it (the sub-pixel ray).
inline std::vector<DetectedMarker> RayNoiseDetections(const ToolGeometry& tool,
                                                      const Rigid3d& ahat_from_tool,
                                                      double along_mm, double across_mm,
                                                      std::mt19937_64& rng) {
  std::vector<DetectedMarker> out;
  for (const Eigen::Vector3d& m : tool.markers_in_tool) {
    const Eigen::Vector3d c = ahat_from_tool * m;
    out.push_back(DetectionAt(c + RayNoise(c, along_mm, across_mm, rng), tool.SurfaceToCentreMm()));
  }
  return out;
}

/// world_from_ahat of a head-worn camera turning at up to ~30 deg/s and moving sideways.
inline Rigid3d TurningCamera(double t_s) {
  return Rigid3d(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.25 * std::sin(2.0 * t_s), Eigen::Vector3d::UnitY()) *
                         Eigen::AngleAxisd(0.1 * std::sin(3.1 * t_s), Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(30.0 * std::sin(1.3 * t_s), 0.0, 0.0));
}

/// `count` spurious detections spread over a box in front of the camera.
inline void AddSpurious(std::vector<DetectedMarker>& detections, int count, std::mt19937_64& rng,
                        const Eigen::Vector3d& centre = {0.0, 0.0, 450.0}, double half_mm = 150.0) {
  std::uniform_real_distribution<double> u(-half_mm, half_mm);
  for (int i = 0; i < count; ++i) {
    detections.push_back(DetectionAt(centre + Eigen::Vector3d(u(rng), u(rng), u(rng)), 5.75));
  }
}

/// A random rotation of up to `max_angle_rad` about a random axis, applied to FacingToolPose.
inline Rigid3d RandomFacingPose(std::mt19937_64& rng, double z_mm, double max_angle_rad = 0.5) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(max_angle_rad * std::abs(u(rng)), axis));
  const Rigid3d base = FacingToolPose({60.0 * u(rng), 60.0 * u(rng), z_mm});
  return Rigid3d(base.rotation * turn, base.translation);
}

}  // namespace tofnav::testing
