// SPDX-License-Identifier: BSD-3-Clause
// A small software rasteriser (orthographic, z-buffer, headlight shading) for report figures.
#pragma once

#include <Eigen/Core>
#include <span>

#include "tofnav/core/image.hpp"
#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav {

/// One mesh to draw: per-vertex colours when `vertex_colours` has one per vertex, else `colour`.
struct MeshLayer {
  const TriangleMesh* mesh = nullptr;
  std::span<const Rgb8> vertex_colours;
  Rgb8 colour = Rgb8(200, 200, 200);
  /// Moves the layer towards the viewer in the z-buffer only [mm], so a surface lying on
  /// another (the registered reconstruction on the CT skin) wins where they coincide.
  double depth_offset_mm = 0.0;
};

/// Orthographic camera: screen (u right, v down, depth towards the viewer) =
/// pixels_per_mm * rotation * (x - centre) + image centre. `rotation` rows are the screen's
/// right, down and towards-viewer axes in the mesh frame.
struct OrthoCamera {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d centre_mm = Eigen::Vector3d::Zero();
  double pixels_per_mm = 1.0;
};

struct RenderOptions {
  int width_px = 360;
  int height_px = 360;
  Rgb8 background = Rgb8(255, 255, 255);
  double ambient = 0.3;  // dimensionless: share of the colour lit regardless of the normal
  void Check() const;    // throws PreconditionError
};

/// A camera orbiting the layers' bounding sphere: it looks from direction (azimuth about z, from
/// -y towards +x; elevation above the xy plane) at the sphere's centre, z up on screen, and
/// fits the sphere in the image with a small margin. Same sphere, same scale for every view.
OrthoCamera OrbitCamera(std::span<const MeshLayer> layers, double azimuth_rad, double elevation_rad,
                        const RenderOptions& options = {});

/// Draws every layer with one z-buffer (nearest surface wins, pixel centres at +0.5) and
/// two-sided Lambert shading from a light at the camera.
Image<Rgb8> RenderMeshes(std::span<const MeshLayer> layers, const OrthoCamera& camera,
                         const RenderOptions& options = {});

/// The report's error colour map (dark blue, cyan, yellow, red) at t in [0, 1], clamped.
Rgb8 ErrorColour(double t);

}  // namespace tofnav
